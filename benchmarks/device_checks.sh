#!/usr/bin/env bash
# The checks that need a device machine, as one command: the CuPy route's agreement with the
# CPU path and its time to solution (issues 39, 50), a whole scan on the GPU and on the CPU,
# where a GPU solve's time goes, and on request the CPU solver's scaling over many cores
# (issue 38). Prepare here first (benchmarks/README.md, "Device checks"): the wheels
# (benchmarks/device_wheels.sh), optionally the scan's bundle (bench_gpu_scan.py prepare) and
# an earlier tree's src/ in .base_src (the same machine's before). Then, with the device
# tool, in one call:
#
#     run  command: bash benchmarks/device_checks.sh
#          carry: [".whl", ".scan_bundle", ".base_src"]   timeout_s: 500
#
# The steps' limits are ceilings for a fresh machine (FFTW plans measured, kernels compiled)
# and add up to 710 s; on 2026-11-28 a fresh H100 machine ran them all in 367 s. The steps
# that measure an issue's target come first: the GPU route against the CPU solver at 512² and
# 2048², elastic and penetration hardness (the CPU solve timed once); 4096² on the device
# alone; the scan (when .scan_bundle is there); the phases of a 2048² solve
# (bench_gpu_phases.py); the before tree (when .base_src is there); the CuPy tests; a
# profile of the host's time. STEPS="baseline baseline_array" times the route's earlier
# versions (cupy-terms, cupy-array) at 2048² and 4096²; STEPS="dispatch scaling" (190 s
# more; scaling measured on 2026-11-26) times a pass of slabs' dispatch on 1-16 threads
# (bench_slab_dispatch.py), then runs benchmark 1 at 2048² on 1, 8, 16, 4 and 2 threads;
# scaling_padded (120 s more, not yet run on a device) a padded 1024² window on 1 and 8
# threads.
# Each step has its own time limit, so that a slow one leaves the others their time, and
# writes its log to $OUT/<step>.log as it runs: what a stopped step printed still comes
# back. Steps run in the order below, whatever the order in STEPS.
# QUICK=1 runs every step on small grids and BACKEND=numpy-array the GPU route's code on
# numpy (BACKEND_BASELINE, BACKEND_BASELINE_ARRAY=numpy-array the baselines'): together they
# try the script on any machine in three minutes.
set -uo pipefail
out=${OUT:-/tmp/device-checks}
mkdir -p "$out"
out=$(cd "$out" && pwd)  # absolute: the benchmark steps run in benchmarks/
failed=0
python=${PYTHON:-python3}
steps=" ${STEPS:-machine warm gpu gpu_large scan phases before tests profile} "
backend=${BACKEND:-cupy}
cores=$(nproc)
if compgen -G ".whl/*.whl" > /dev/null; then
    "$python" -m pip install --quiet --no-index --no-deps --no-compile --no-cache-dir \
        --upgrade --target /tmp/device-site .whl/*.whl || exit 1
    export PYTHONPATH=/tmp/device-site
fi
# the working tree's code, not the wheel's; the wheel gives the package's metadata
export PYTHONPATH="$PWD/src${PYTHONPATH:+:$PYTHONPATH}" PYTHONUNBUFFERED=1

if [[ ${QUICK:-0} == 1 ]]; then
    gpu_sizes=(64 128) large_sizes=(256) scaling_size=256 repeats=1 threads=(1 2)
    padded_size=128 padded_threads=(1 2)
    profile_size=128 baseline_sizes=(128) scan_rounds=1
else
    gpu_sizes=(512 2048) large_sizes=(4096) scaling_size=2048 repeats=3 threads=(1 8 16 4 2)
    padded_size=1024 padded_threads=(1 8)
    profile_size=2048 baseline_sizes=(2048 4096) scan_rounds=2
fi

step() {  # step NAME SECONDS COMMAND...: run COMMAND for at most SECONDS, logged
    local name=$1 limit=$2
    shift 2
    [[ $steps == *" $name "* ]] || return 0
    echo "== $name (at most $limit s): $*"
    timeout "$limit" "$@" 2>&1 | tee "$out/$name.log"
    local status=${PIPESTATUS[0]}
    echo "== $name: exit $status (124: stopped at its limit)"
    [[ $status == 0 ]] || failed=1
}

step machine 20 bash -c "nvidia-smi --query-gpu=name,memory.total,driver_version \
    --format=csv; lscpu | grep -E 'Model name|^CPU\(s\)|L3'; \"$python\" -c 'import sys, \
    numpy, numba, pyfftw, amontons; print(sys.version); print(\"numpy\", numpy.__version__, \
    \"numba\", numba.__version__, \"pyfftw\", pyfftw.__version__)'; \"$python\" -c 'import \
    cupy; print(\"cupy\", cupy.__version__, cupy.cuda.runtime.getDeviceCount(), \"device(s)\")'"
# the numba kernels compile once into their disk cache (26-46 s on a 2-core VM; over 60 s on
# a fresh device machine, 2026-11-28)
step warm 90 "$python" -c "from amontons.contact.kernel_cache import main; main()"
cd benchmarks || exit 1
step gpu 170 "$python" bench_gpu.py --backend "$backend" --sizes "${gpu_sizes[@]}" \
    --laws elastic hardness --threads "$cores" --repeats "$repeats" --cpu-repeats 1
step gpu_large 60 "$python" bench_gpu.py --backend "$backend" --device-only \
    --sizes "${large_sizes[@]}" --repeats "$repeats"
step baseline 60 "$python" bench_gpu.py --backend "${BACKEND_BASELINE:-cupy-terms}" \
    --device-only --sizes "${baseline_sizes[@]}" --repeats "$repeats"
# where a solve's time goes, phase by phase, each between two synchronisations
step phases 40 bash -c "\"$python\" bench_gpu_phases.py --backend $backend --size $profile_size \
    --bc periodic && \"$python\" bench_gpu_phases.py --backend $backend --size $profile_size \
    --bc padded"
# the route as an earlier tree has it (.base_src/src, carried), on the same machine: the
# before of a change (benchmarks/README.md, "The GPU route")
if [[ -d ../.base_src/src ]]; then
    step before 60 env PYTHONPATH="$(cd ../.base_src/src && pwd):${PYTHONPATH#*:}" \
        "$python" bench_gpu.py --backend "$backend" --device-only \
        --sizes "${baseline_sizes[@]}" --repeats "$repeats"
fi
# where the host's time goes in the GPU route's solves: the 45 costliest functions
step profile 40 bash -c "\"$python\" -m cProfile -s tottime bench_gpu.py --backend $backend \
    --device-only --sizes $profile_size --repeats 3 | head -75"
step dispatch 20 "$python" bench_slab_dispatch.py --thread-counts "${threads[@]}" --calls 1000
step scaling 170 "$python" bench_iteration.py --sizes "$scaling_size" --bc periodic \
    --paths fused --thread-counts "${threads[@]}" --repeats "$repeats"
step scaling_padded 120 "$python" bench_iteration.py --sizes "$padded_size" --bc non-periodic \
    --paths fused --thread-counts "${padded_threads[@]}" --repeats "$repeats"
cd .. || exit 1
# a whole scan (the bundle of bench_gpu_scan.py prepare, carried) on the GPU and on the CPU
if [[ -f .scan_bundle/jobs.json ]]; then
    step scan 150 "$python" benchmarks/bench_gpu_scan.py run --bundle .scan_bundle \
        --backends "$backend" cpu --threads "$cores" --rounds "$scan_rounds"
fi
step tests 80 "$python" -m pytest -q -p no:cacheprovider \
    tests/contact/test_array_kernels.py tests/contact/test_device_kernels.py \
    tests/contact/test_thread_pools.py
cd benchmarks || exit 1
step baseline_array 40 "$python" bench_gpu.py --backend "${BACKEND_BASELINE_ARRAY:-cupy-array}" \
    --device-only --sizes "${baseline_sizes[0]}" --repeats "$repeats"
exit "$failed"
