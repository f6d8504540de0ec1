"""Regenerate brdf/baselines/charlie_albedo.json: the Charlie sheen's directional albedo
E(cos theta, roughness) by quadrature on brdf.baselines.charlietable's grid (deterministic: the
same bytes each run), and print the time it took and the table's range.

Run: ``PYTHONPATH=. .venv/bin/python bench/charlie_albedo_table.py``.
"""

from __future__ import annotations

import time

from brdf.baselines import charlietable
from brdf.baselines.charlie import albedo_table


def main() -> None:
    t0 = time.perf_counter()
    values = albedo_table()
    dt = time.perf_counter() - t0
    charlietable.write(values)
    print(f"Charlie albedo table {values.shape[0]} cos x {values.shape[1]} roughness in "
          f"{dt:.1f} s: E from {values.min():.3g} to {values.max():.3g}; "
          f"wrote {charlietable.PATH}")


if __name__ == "__main__":
    main()
