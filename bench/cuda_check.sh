#!/bin/sh
# The cuda_ad_rgb checks, for a machine with an NVIDIA GPU (the device tool's machine):
# the plugin's float32 eval against brdf.Fabric for every preset and variant, the shared
# kernel, Mitsuba's chi-square test of its sampler, direct light against the built-in
# renderer, and the cylinder's render time in cuda_ad_rgb beside the built-in renderer.
# Needs numpy, scipy and mitsuba importable by python3 (PYTHON=... to choose another).
# Usage: sh bench/cuda_check.sh   (about 3 minutes; prints pytest's summary and the figures)
set -e
PY=${PYTHON:-python3}
cd "$(dirname "$0")/.."
export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}"
nvidia-smi --query-gpu=name,memory.total --format=csv,noheader || true
$PY -m pytest -q -p no:cacheprovider -rs -k cuda_ad_rgb \
    tests/test_reports_mitsuba.py tests/test_reports_mitsuba_render.py
$PY bench/bench_render.py velvet --variant cuda_ad_rgb --rounds 2
