#!/usr/bin/env bash
# The CUDA check, in one go: the fast tests with TDEM_ARCH=gpu (one process per test
# file, so that a file that breaks the CUDA context fails alone), then the DEM pack,
# the PCMM column, the superellipse bed and the 3D sphere pack benchmarks on the GPU
# at large sizes.
#
#   bash benchmarks/gpu_check.sh [OUTDIR]
#
# Wheels in .whl/ (taichi, meshio, dill for the machine's Python) are installed into
# /tmp/site first when the machine's Python lacks them (it cannot reach PyPI).
# Environment:
#   SIDE      discs per row of the DEM pack and PCMM column (default 1000: 1M)
#   SE_COLS   columns of the superellipse bed, 200 rows (default 1000: 200,000)
#   SCALE3D   the 3D sphere pack's box widened in x and y by this factor (default
#             21.25: 1.0M spheres, the 47,068 of benchmarks/pack3d.py times 21.25)
#   TESTS     0 to skip the tests;  TEST_TIME  limit per test file in s (default 150)
#   TEST_GLOB the test files (default tests/test_*.py)
#   PROBE     0 to skip the first probe (small shaped and PCMM runs with Taichi's
#             advanced optimisation on and off; tdem turns it off on CUDA:
#             tdem.backend.advanced_optimization)
#   ARCH      gpu (default) or cpu, to try this script on a machine without CUDA
set -uo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-${OUT:-out/gpu_check}}
mkdir -p "$OUT"
SIDE=${SIDE:-1000}
SE_COLS=${SE_COLS:-1000}
ARCH=${ARCH:-gpu}
export PYTHONUNBUFFERED=1
if ! python3 -c "import taichi, meshio" 2>/dev/null && ls .whl/*.whl >/dev/null 2>&1; then
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
        --target /tmp/site .whl/*.whl || exit 1
    export PYTHONPATH=/tmp/site:$PWD
else
    export PYTHONPATH=$PWD
fi
(nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader || true) \
    | tee "$OUT/machine.txt"
python3 -W ignore -c "import platform, taichi; print('python', platform.python_version(), 'taichi', taichi.__version__)" \
    | tee -a "$OUT/machine.txt"

probe() {  # NAME ADVOPT COMMAND...: one line, ok or the error's last line
    local name=$1 opt=$2; shift 2
    local log="$OUT/probe_${name}_opt${opt}.txt"
    if TDEM_ADVANCED_OPTIMIZATION=$opt timeout 150 "$@" >"$log" 2>&1; then
        echo "probe $name advanced_optimization=$opt: ok ($(grep PEER "$log" | head -1))"
    else
        echo "probe $name advanced_optimization=$opt: FAILED: $(grep -m1 -E 'Error|error' "$log")"
    fi
}
if [ "${PROBE:-1}" != 0 ]; then
    echo "== probes"
    for opt in 1 0; do
        probe superellipse $opt python3 benchmarks/superellipse.py --arch "$ARCH" --cols 50 \
            --rows 20 --no-disc --warmup 200 --steps 200 &
        probe pcmm $opt python3 benchmarks/pcmm.py --arch "$ARCH" --side 60 --warmup 100 \
            --steps 100 --rounds 1 --no-dem &
        probe ellipsoids $opt python3 benchmarks/pack3d.py --arch "$ARCH" --ellipsoids \
            --scale 0.1 --warmup 100 --steps 100 &
    done
    wait
fi | tee "$OUT/probes.txt"
echo "TDEM_ADVANCED_OPTIMIZATION=${TDEM_ADVANCED_OPTIMIZATION:-} (empty: tdem's default)" \
    | tee -a "$OUT/machine.txt"

if [ "${TESTS:-1}" != 0 ]; then
    echo "== fast tests, TDEM_ARCH=$ARCH, one process per file"
    # the file readers' tests (vtk) and the ParaView test do not depend on the arch
    ls ${TEST_GLOB:-tests/test_*.py} | grep -v -E "test_io.py|test_pcmm_io.py|test_paraview.py" \
        | xargs -P 12 -I{} sh -c 'echo "{}: $(TDEM_ARCH='"$ARCH"' timeout '"${TEST_TIME:-150}"' \
            python3 -W ignore -m pytest -q -p no:cacheprovider -o addopts="" -m "not slow" \
            -p no:benchmark {} 2>&1 | tail -1)"' | sort | tee "$OUT/tests.txt"
    awk '/failed|error|Error|Timeout/ || !/passed|skipped|deselected/ {print "NOT PASSED: " $0}' \
        "$OUT/tests.txt"
fi

echo "== DEM pack, ${SIDE}x${SIDE} discs"
timeout 100 python3 benchmarks/pack2d.py --arch "$ARCH" --rows "$SIDE" --cols "$SIDE" \
    --warmup 500 --steps 1000 2>&1 | tee "$OUT/pack2d.txt" | tail -3
echo "== PCMM column, ${SIDE}x${SIDE} particles"
timeout 120 python3 benchmarks/pcmm.py --arch "$ARCH" --side "$SIDE" --warmup 300 \
    --steps 300 --rounds 3 --no-dem 2>&1 | tee "$OUT/pcmm.txt" | tail -5
echo "== superellipse bed, ${SE_COLS} x 200"
timeout 80 python3 benchmarks/superellipse.py --arch "$ARCH" --cols "$SE_COLS" --no-disc \
    --warmup 500 --steps 500 2>&1 | tee "$OUT/superellipse.txt" | tail -12
echo "== 3D sphere pack, ${SCALE3D:-21.25} x 47,068 spheres"
timeout 200 python3 benchmarks/pack3d.py --arch "$ARCH" --scale "${SCALE3D:-21.25}" \
    --warmup 300 --steps 1000 2>&1 | tee "$OUT/pack3d.txt" | tail -3
