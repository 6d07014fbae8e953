#!/usr/bin/env bash
# The checks that need a GPU, as one bounded script: the OpenCL device and its compiler's warnings, the
# step's throughput at 100k and 1M particles (per-tile layout as chosen, and the CPU's 32 tiles beside
# it), WCSPH against DFSPH on a 1M-particle dam break, the renderer through the GPU's EGL, and the unit
# tests that run on the device. Every step has its own time limit and the script goes on past a
# failure; its log goes to OUT/gpu-check.log, the tests' to OUT/tests.log, frames to OUT/dam-1M.png and
# OUT/frames/. thaw_tests reads configs/ and tools/ from the source folder it was built in.
#
#   scripts/gpu-check.sh [BUILD_DIR] [OUT]         e.g. scripts/gpu-check.sh build /tmp/gpu
#
# Not part of the test suite (CI has no GPU); the figures it printed are quoted in docs/BENCHMARKS.md.
set -u
BUILD=${1:-build}
OUT=${2:-gpu-check}
THAW="$BUILD/thaw"
# GPU_CHECK_STEPS: the steps to run (default: all); GPU_CHECK_TESTS: the tests' gtest filter;
# GPU_CHECK_TEST_SECONDS: their time limit (default 240; on an H200 they took about 3 minutes).
STEPS=" ${GPU_CHECK_STEPS:-info build-log throughput throughput-32tiles throughput-512tiles dam-1M-wcsph dam-1M-dfsph scene-default scene-ice-bunny substances-100k substances-1M bodies render-bench render-png tests} "
mkdir -p "$OUT"
LOG="$OUT/gpu-check.log"
: >"$LOG"
step() {  # step NAME SECONDS COMMAND...: runs COMMAND with a time limit, its output appended to the log
  local name=$1 limit=$2
  shift 2
  [[ "$STEPS" == *" $name "* ]] || return 0
  local t0=$SECONDS
  echo "== $name: $*" >>"$LOG"
  timeout -k 5 "$limit" "$@" >>"$LOG" 2>&1
  local rc=$?
  echo "== $name: rc $rc, $((SECONDS - t0)) s (limit $limit s)" | tee -a "$LOG"
}

step info 20 "$THAW" info
# The vendor compiler's warnings for every program a melting, flowing scene builds (5 steps).
THAW_CL_BUILD_LOG=1 step build-log 30 "$THAW" run ice-on-plate --steps 5 --quiet --no-progress
step throughput 60 "$THAW" bench throughput --sizes 100000,1000000 --steps 30
THAW_TILES=32 step throughput-32tiles 60 "$THAW" bench throughput --sizes 100000,1000000 --steps 30
THAW_TILES=512 step throughput-512tiles 45 "$THAW" bench throughput --sizes 1000000 --steps 30
# 982k water particles in the dam break (0.25 x 0.2 x 0.5 m of water at 0.2/68 m: the walled x and y
# extents must be whole numbers of spacings).
for p in wcsph dfsph; do
  step "dam-1M-$p" 70 "$THAW" run dam-break --set spacing=0.00294117647 --set solver.pressure=$p --until 0.1 \
    --no-progress --state-out "$OUT/dam-1M-$p.state"
done
# Melting scenes with free ice, heat and a dryer (the service's default scene), and the ice bodies' passes.
step scene-default 60 "$THAW" run default --until 0.5 --no-progress --frames "$OUT/frames" --every 2000
step scene-ice-bunny 60 "$THAW" run ice-bunny --until 0.5 --no-progress
# The substance stage's cost on the benchmark block (docs/SUBSTANCES.md): none, one and three bulk substances,
# and a surface-active one beside two bulk ones, at 97k and 1M particles.
substance_runs() {
  local size=$1 spacing=$2
  local bulk='"salt": {"diffusivity": 1.5e-9, "molar_mass": 0.05844, "dissociation": 2}, "sugar": {"diffusivity": 5e-10}'
  local soap='"soap": {"kind": "surface_active", "diffusivity": 1e-9}'
  for set in '' '{"dye": {"diffusivity": 1e-9}}' "{\"dye\": {\"diffusivity\": 1e-9}, $bulk}" \
    "{\"dye\": {\"diffusivity\": 1e-9}, $soap}" "{\"dye\": {\"diffusivity\": 1e-9}, $bulk, $soap}"; do
    local args=(--set "spacing=$spacing")
    if [ -n "$set" ]; then
      local conc
      conc=$(echo "$set" | grep -o '"[a-z]*": {"' | sed 's/: {"//' | sed 's/$/: {"concentration": 1}/' | paste -sd, -)
      args+=(--set "substances=$set" --set "fluids[0].substances={$conc}")
    fi
    echo "== $size particles, substances: ${set:-none}"
    "$THAW" run bench/scenes/block.json --steps 200 --no-progress "${args[@]}"
  done
}
export -f substance_runs
export THAW
step substances-100k 90 bash -c 'substance_runs 97k 0.002'
step substances-1M 200 bash -c 'substance_runs 1M 0.00092'
step bodies 40 "$THAW" bench bodies --size 1000000
step render-bench 40 "$THAW" bench render --sizes 100000,1000000
if [ -f "$OUT/dam-1M-dfsph.state" ]; then
  step render-png 20 "$THAW" render "$OUT/dam-1M-dfsph.state" --out "$OUT/dam-1M.png" --size 1280x720
fi
rm -f "$OUT"/dam-1M-*.state
# The unit tests that run on the OpenCL device and the renderer, and the service's smoke tests (its
# browser and sanitizer tests need Chromium and the sanitizer build, which a GPU machine need not have;
# ServeSmoke needs /usr/bin/python3 with the websockets package).
LOG="$OUT/tests.log"
: >"$LOG"
step tests "${GPU_CHECK_TEST_SECONDS:-240}" "$BUILD/thaw_tests" \
  --gtest_filter="${GPU_CHECK_TESTS:-KernelBuild.*:ClRuntime.*:DfsphTest.*:DfsphScene.*:SolverTest.*:NeighbourGrid.*:HeatTest.*:RigidIceTest.*:IceBodiesTest.*:EmitterTest.*:PhotonTracerTest.*:RenderTest.*:EglContextTest.*:PickingTest.*:ParticleView.*:SliceView.*:StateFileTest.*:Validation.*:ThroughputBench.*:SessionTest.*:RenderWorkerTest.*:ServeSmoke.*:ServeCtl.*}"
