"""Time to write a full MERL .binary table (90 x 90 x 180 bins) from a preset.

Usage: python bench/bench_merl_write.py [PRESET] [ROTATIONS]
(defaults: linen_plain, 8 fabric rotations averaged per bin).
"""

import sys
import tempfile
import time
from pathlib import Path

import brdf
import gonio


def main(preset="linen_plain", rotations=8):
    fab = brdf.fabric(preset)
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / f"{preset}.binary"
        t0 = time.perf_counter()
        gonio.write_merl(fab, path, rotations=rotations)
        dt = time.perf_counter() - t0
        size = path.stat().st_size
        missing = gonio.load_merl(path).missing_values
    n = 90 * 90 * 180
    print(f"MERL write, preset {preset}, {rotations} rotations: {dt:.1f} s for {n} bins "
          f"({n * rotations / dt / 1e6:.2f} M evaluations/s), {size} bytes, "
          f"{missing} missing (below-horizon) entries")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "linen_plain",
         int(sys.argv[2]) if len(sys.argv) > 2 else 8)
