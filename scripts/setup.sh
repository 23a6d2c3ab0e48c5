#!/usr/bin/env bash
# Installs everything dyngen needs on a fresh Debian/Ubuntu machine:
# system packages (C compiler, NLopt, Eigen) and the Python package with its
# test dependencies. Safe to run twice.
set -euo pipefail
cd "$(dirname "$0")/.."

need_apt=()
command -v cc >/dev/null 2>&1 || need_apt+=(gcc)
command -v c++ >/dev/null 2>&1 || need_apt+=(g++)
command -v cmake >/dev/null 2>&1 || need_apt+=(cmake)
[ -f /usr/include/nlopt.h ] || need_apt+=(libnlopt-dev)
[ -d /usr/include/eigen3 ] || need_apt+=(libeigen3-dev)
command -v pkg-config >/dev/null 2>&1 || need_apt+=(pkg-config)
# Firmware checks: the ARM cross compiler and newlib's headers and libm (tests/test_firmware.py)
command -v arm-none-eabi-gcc >/dev/null 2>&1 || need_apt+=(gcc-arm-none-eabi)
[ -f /usr/include/newlib/math.h ] || need_apt+=(libnewlib-arm-none-eabi)
# The benchmarks (bench/run_all.py) also count instructions with valgrind: DYNGEN_BENCH=1 adds it.
if [ "${DYNGEN_BENCH:-0}" = 1 ]; then command -v valgrind >/dev/null 2>&1 || need_apt+=(valgrind); fi

if [ ${#need_apt[@]} -gt 0 ]; then
  echo "setup: installing system packages: ${need_apt[*]}"
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi

PY=${PYTHON:-python3}
EXTRAS="test"
[ "${DYNGEN_BENCH:-0}" = 1 ] && EXTRAS="test,bench"  # the benchmarks' CasADi (bench/bench_dynamics.py)
echo "setup: installing the dyngen Python package (editable, with the $EXTRAS extras)"
if ! $PY -m pip install -q --disable-pip-version-check -e ".[$EXTRAS]" 2>/tmp/dyngen-pip.err; then
  if grep -q externally-managed /tmp/dyngen-pip.err; then  # Debian's system Python (PEP 668)
    $PY -m pip install -q --disable-pip-version-check --break-system-packages -e ".[$EXTRAS]"
  else
    cat /tmp/dyngen-pip.err >&2; exit 1
  fi
fi

# The extractor driver is a static program, compiled once per user into the per-user cache
# (about a minute); each arm then only links its generated C to it (extraction/driver.py).
echo "setup: compiling the extractor driver once"
$PY -c "from dyngen.extraction.driver import build_core; build_core()"
