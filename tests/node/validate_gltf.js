// The Khronos glTF validator's report of each file named: one JSON line a file
// (tests/test_analysis_export.py; npm install --prefix tests/node installs the validator).
const validator = require(__dirname + "/node_modules/gltf-validator");
const fs = require("fs");
(async () => {
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    console.log(JSON.stringify({file: file, errors: report.issues.numErrors,
                                warnings: report.issues.numWarnings,
                                messages: report.issues.messages.slice(0, 5)}));
  }
})();
