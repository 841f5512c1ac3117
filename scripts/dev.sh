#!/usr/bin/env bash
# One entry point for a new machine: installs what is missing (Debian 12), builds, and runs.
#   scripts/dev.sh demo          build, then run `probecast demo` (writes out/)
#   scripts/dev.sh test          build, then run the whole test suite (ctest)
#   scripts/dev.sh core-test     the Vulkan-free build (codec, imaging, service, their tests) in build-core, and its tests
#   scripts/dev.sh memsafe       sanitizer build (ASan + UBSan) and the codec and bus-format tests under it
#   scripts/dev.sh fuzz [SECS]   libFuzzer build (clang-14) and a bounded fuzz run of the codec, the bus decoder, scene manifests, the client's checks of a server, glTF scenes, Looking Glass calibrations and the browser's decoder
#   scripts/dev.sh python        `pip install ./python` into build-python/venv, and the Python tests against it
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
JOBS=$(nproc 2>/dev/null || echo 2)
WERROR=${PROBECAST_WERROR:-OFF}
[ "${CI:-}" = "true" ] && WERROR=ON

# The Python module and its tests use the system Python (Debian's numpy, pytest, pybind11), not
# whatever python3 comes first on PATH.
PYTHON_ARGS=()
[ -x /usr/bin/python3 ] && PYTHON_ARGS=(-DPython3_EXECUTABLE=/usr/bin/python3)

configure_and_build() {  # DIR [cmake args...]
  local dir=$1
  shift
  set -- "${PYTHON_ARGS[@]}" "$@"
  if [ ! -f "$dir/build.ninja" ]; then
    cmake -S . -B "$dir" -G Ninja -DPROBECAST_WERROR="$WERROR" "$@"
  else
    cmake "$dir" -DPROBECAST_WERROR="$WERROR" "$@" >/dev/null
  fi
  cmake --build "$dir" -j "$JOBS"
}

cmd=${1:-demo}
shift || true
bash scripts/setup.sh

case "$cmd" in
  demo)
    configure_and_build build
    ./build/probecast demo "$@"
    ;;
  test)
    configure_and_build build
    ctest --test-dir build --output-on-failure -j "$JOBS" "$@"
    ;;
  core-test)
    # What an engine embedding the decoder side builds: no Vulkan SDK, no glslang. Vulkan is
    # disabled outright, so a find_package(Vulkan) creeping into this configuration fails it.
    configure_and_build build-core -DPROBECAST_RENDERER=OFF -DCMAKE_DISABLE_FIND_PACKAGE_Vulkan=ON
    if grep -E '^(Vulkan|glslang|PROBECAST_SPIRV_VAL)' build-core/CMakeCache.txt; then
      echo "core-test: the Vulkan-free configuration looked up Vulkan or glslang" >&2
      exit 1
    fi
    ctest --test-dir build-core --output-on-failure -j "$JOBS" "$@"
    ;;
  memsafe)
    configure_and_build build-asan -DPROBECAST_SANITIZE=ON -DPROBECAST_APP=OFF
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      ctest --test-dir build-asan --output-on-failure -j "$JOBS" -L 'codec|bus' "$@"
    ;;
  fuzz)
    # Seven targets share the time: the codec's decoders (half), the probe bus decoder, scene
    # manifests, the client's checks of what a server sends, glTF scenes, Looking Glass
    # calibrations and the browser's decoder (a tenth each).
    secs=${1:-60}
    configure_and_build build-fuzz -DPROBECAST_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_C_COMPILER=clang-14
    for target in codec bus manifest client gltf calibration web; do
      if [ "$target" = codec ]; then
        seeds=build-fuzz/seeds corpus=build-fuzz/corpus share=$(( (secs + 1) / 2 ))
      else
        seeds=build-fuzz/seeds-$target corpus=build-fuzz/corpus-$target share=$(( secs / 10 ))
      fi
      [ "$share" -ge 1 ] || share=1
      mkdir -p "$seeds" "$corpus"
      "./build-fuzz/fuzz/${target}_fuzz_seeds" "$seeds"
      echo "fuzz: running ${target}_fuzz for ${share}s"
      log=build-fuzz/fuzz-$target.log
      rc=0
      # Undefined behaviour fails the run, as a crash does (UBSan only reports it otherwise).
      UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      "./build-fuzz/fuzz/${target}_fuzz" -max_total_time="$share" -print_final_stats=1 -artifact_prefix=build-fuzz/ \
        "$corpus" "$seeds" >"$log" 2>&1 || rc=$?
      grep -E '^(Done|stat::(number_of_executed_units|new_units_added)|==[0-9]+==|SUMMARY|.*artifact)' "$log" || true
      if [ "$rc" -ne 0 ]; then
        tail -40 "$log"
        echo "fuzz: ${target}_fuzz found a failure (rc $rc, log $log)"
        exit 1
      fi
    done
    echo "fuzz: clean after ${secs}s"
    ;;
  python)
    # The module as a Python user installs it (python/README.md): a virtual environment over
    # Debian's numpy, pytest, pybind11 and scikit-build-core, `pip install ./python` without build
    # isolation or an index, its CMake build kept in build-python/build. The tests then run from
    # build-python/ against the installed module, never a build tree's.
    py=/usr/bin/python3
    [ -x "$py" ] || py=python3
    venv=$ROOT/build-python/venv
    [ -x "$venv/bin/python" ] || "$py" -m venv --system-site-packages "$venv"
    CMAKE_BUILD_PARALLEL_LEVEL=$JOBS "$venv/bin/python" -m pip install --no-build-isolation --no-index \
      --config-settings=build-dir="$ROOT/build-python/build" \
      --config-settings=cmake.define.PROBECAST_WERROR="$WERROR" ./python
    # The C++ side of the byte-for-byte tests, from the same configuration.
    cmake --build build-python/build -j "$JOBS" --target probecast_python_golden
    site=$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["platlib"])')
    cd build-python
    unset PYTHONPATH
    module=$("$venv/bin/python" -c 'import probecast; print(probecast.__file__)')
    echo "python: probecast $("$venv/bin/python" -c 'import importlib.metadata as m; print(m.version("probecast"))') from $module"
    PROBECAST_EXPECT_MODULE_DIR=$site PROBECAST_GOLDEN=$ROOT/build-python/build/python/probecast_python_golden \
      PROBECAST_TEST_DATA=$ROOT/tests/data "$venv/bin/python" -m pytest -q -p no:cacheprovider "$ROOT/python/tests" "$@"
    ;;
  *)
    echo "usage: scripts/dev.sh demo|test|core-test|memsafe|fuzz|python [args]" >&2
    exit 2
    ;;
esac
