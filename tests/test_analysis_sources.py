"""analysis.sources (what a FABRIC names) and analysis.fabricfile (a fabric as a .json or .xml
file): each kind resolved, and each bad or hostile source one line naming it."""

import json
import math
import os

import numpy as np
import pytest

import brdf
from analysis import sources
from analysis.fabricfile import (MAX_FILE_BYTES, fabric_from_xml, plugin_dict, plugin_xml,
                                 read_fabric_file)

WI = brdf.directions.from_angles(np.radians([10.0, 40.0, 70.0]), np.radians([0.0, 30.0, 200.0]))
WO = brdf.directions.from_angles(np.radians([20.0, 35.0, 60.0]), np.radians([180.0, 90.0, 5.0]))


@pytest.mark.parametrize("name", brdf.PRESETS)
def test_xml_and_json_round_trip_every_preset(name, tmp_path):
    fab = brdf.fabric(name, masking=False, gap="outgoing", rotation=0.3)
    (tmp_path / "f.xml").write_text(plugin_xml(fab))
    (tmp_path / "f.json").write_text(json.dumps(plugin_dict(fab)))
    for suffix in (".xml", ".json"):
        back = read_fabric_file(tmp_path / f"f{suffix}")
        assert back.threads == fab.threads and back.name == name
        assert back.options["masking"] is False and back.options["gap"] == "outgoing"
        assert math.isclose(back.options["rotation"], 0.3, rel_tol=1e-12)
        np.testing.assert_array_equal(back.eval(WI, WO), fab.eval(WI, WO))


def test_xml_inside_a_scene_and_by_hand():
    text = ('<scene version="3.0.0"><bsdf type="diffuse" id="floor"/>'
            '<bsdf type="microcylinder" id="cloth"><string name="fabric" value="velvet"/>'
            '<float name="eta1" value="1.5"/><rgb name="albedo2" value="0.1, 0.2, 0.3"/>'
            '<boolean name="masking" value="false"/><integer name="tangent_samples" '
            'value="8"/><string name="offsets2" value="-80, 80"/>'
            '<string name="lengths2" value="1"/></bsdf></scene>')
    fab = fabric_from_xml(text)
    t1, t2 = fab.threads
    assert t1.eta == 1.5 and t2.eta == 1.46 and t2.albedo == (0.1, 0.2, 0.3)
    assert t2.offsets == (-80.0, 80.0)
    assert fab.options["masking"] is False and fab.options["tangent_samples"] == 8


@pytest.mark.parametrize("text, message", [
    ('<!DOCTYPE x [<!ENTITY a "b">]><bsdf type="microcylinder"/>', "document type"),
    ('<bsdf type="microcylinder"><float name="eta1" value="1.5">', "not well-formed"),
    ('<bsdf type="diffuse"/>', 'no <bsdf type="microcylinder">'),
    ('<bsdf type="microcylinder"><spectrum name="eta1" value="1"/></bsdf>', "<spectrum>"),
    ('<bsdf type="microcylinder"><float name="eta1" value="x"/></bsdf>', "eta1 must be a float"),
    ('<bsdf type="microcylinder"><float name="eta1" value="1.5"/><float name="eta1" '
     'value="1.4"/></bsdf>', "'eta1' is given twice"),
    ('<bsdf type="microcylinder"><boolean name="masking" value="maybe"/></bsdf>',
     "masking must be true or false"),
    ('<bsdf type="microcylinder"><float name="eta9" value="1.5"/></bsdf>',
     "unknown microcylinder parameter"),
    ('<bsdf type="microcylinder"><string name="fabric" value="denim"/></bsdf>',
     "unknown fabric 'denim'"),
])
def test_bad_xml_is_one_line(text, message):
    with pytest.raises(ValueError) as info:
        fabric_from_xml(text)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_fabric_files_are_read_defensively(tmp_path):
    good = tmp_path / "good.xml"
    good.write_text(plugin_xml(brdf.fabric("velvet")))
    link = tmp_path / "link.xml"
    link.symlink_to(good)
    big = tmp_path / "big.json"
    big.write_text('{"type": "microcylinder", "fabric": "velvet"}' + " " * MAX_FILE_BYTES)
    nested = tmp_path / "nested.json"
    nested.write_text("[" * 100000 + "]" * 100000)
    other = tmp_path / "other.json"
    other.write_text('{"type": "diffuse"}')
    for path, message in ((link, "a symbolic link"), (big, "more than the"),
                          (nested, "unreadable JSON"), (other, "'diffuse'"),
                          (tmp_path / "f.toml", "ends in .json or .xml")):
        with pytest.raises(ValueError) as info:
            read_fabric_file(path)
        msg = str(info.value)
        assert msg.startswith(str(path)) and message in msg and "\n" not in msg, msg


def test_resolve_each_kind(fit_folder, tmp_path):
    folder, _ = fit_folder
    pre = sources.resolve("velvet")
    assert (pre.kind, pre.label, pre.path, pre.preset) == ("preset", "velvet", None, "velvet")
    fit = sources.resolve(folder)
    assert (fit.kind, fit.label, fit.path, fit.preset) == ("fit", folder.name, folder, "velvet")
    assert fit.brdf.options["masking"] is False            # the fit's own options
    assert sources.resolve(folder / "results.json").brdf.threads == fit.brdf.threads
    (tmp_path / "mine.xml").write_text(plugin_xml(fit.brdf))
    xml = sources.resolve(tmp_path / "mine.xml")
    assert (xml.kind, xml.label, xml.preset) == ("xml", "mine", "velvet")
    assert xml.brdf.threads == fit.brdf.threads and xml.model == "microcylinder"
    changed = sources.resolve(folder, options={"masking": True})
    assert changed.brdf.options["masking"] is True and changed.brdf.threads == fit.brdf.threads


def test_resolve_refusals(tmp_path):
    (tmp_path / "notafit").mkdir()
    (tmp_path / "t.exr").write_bytes(b"x")
    for text, message in (("denim", "FABRIC 'denim': not a preset (linen_plain"),
                          ("", "FABRIC is empty"),
                          (tmp_path / "notafit", "not a fit folder"),
                          (tmp_path / "t.exr", "not a fabric source; expected a preset")):
        with pytest.raises(ValueError) as info:
            sources.resolve(text)
        assert message in str(info.value) and "\n" not in str(info.value)
    with pytest.raises(ValueError, match="--fit 'denim'"):
        sources.resolve("denim", what="--fit")
    with pytest.raises(ValueError, match="given twice"):
        sources.resolve_all(["velvet", "velvet"])


def test_a_measured_table_only_where_any_brdf_is_taken(shared_data):
    felt = shared_data / "rgl" / "acrylic_felt_white_rgb.bsdf"
    with pytest.raises(ValueError, match="not a fabric source"):
        sources.resolve(felt)
    src = sources.resolve(felt, tables=True)
    assert (src.kind, src.label, src.model, src.is_fabric) == \
        ("table", "acrylic_felt_white_rgb", "measured", False)
    assert np.all(np.isfinite(src.brdf.eval(WI, WO)))
    with pytest.raises(ValueError, match="takes no model option"):
        src.with_options(masking=False)
    with pytest.raises(ValueError, match="not a fabric"):
        src.fabric
    assert "measured table (.bsdf or .binary)" in sources.accepted(tables=True)


def test_one_check_of_a_preset_name():
    assert brdf.check_preset("velvet") == "velvet"
    for bad in ("denim", None, 3):
        with pytest.raises(ValueError, match="valid presets are linen_plain"):
            brdf.check_preset(bad)
    assert os.sep not in sources.resolve("silk_shot").label
