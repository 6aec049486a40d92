#!/usr/bin/env bash
# Fill .whl/ with the wheels a device machine lacks for benchmarks/device_checks.sh: the
# project itself (built here, pure Python) and what its solver and tests import beyond the
# device image's packages (numpy, scipy, numba, cupy, threadpoolctl, pytest, pyyaml, attrs,
# typing-extensions are there; nothing can be fetched there). Writes .whl/ in the
# repository root, from anywhere:
#
#     bash benchmarks/device_wheels.sh          # for the device's Python, 3.12
#     bash benchmarks/device_wheels.sh 3.11     # for another Python (to try the checks here)
#
# .whl/ is ignored by git; the device tool takes it along with carry: [".whl"].
set -euo pipefail
cd "$(dirname "$0")/.."
py_version=${1:-3.12}
python=${PYTHON:-python3}
missing=(pyfftw jsonschema jsonschema-specifications referencing rpds-py ptufile pylibCZIrw
    validators xmltodict)
rm -rf .whl
mkdir .whl
"$python" -m pip wheel --quiet --no-deps --wheel-dir .whl .
"$python" -m pip download --quiet --no-deps --only-binary=:all: --dest .whl \
    --python-version "$py_version" --implementation cp \
    --platform manylinux_2_28_x86_64 --platform manylinux_2_17_x86_64 \
    --platform manylinux2014_x86_64 "${missing[@]}"
du -sh .whl
ls .whl
