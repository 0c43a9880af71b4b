#!/usr/bin/env bash
# Builds the fppm Python module, installs it into a venv under target/ and runs its pytest suite
# (crates/python/tests) against it and against the fppm command of this checkout, which it builds
# too (the bit-identity tests compare the two). `.ci/run` calls it; it also works alone.
#
# The venv (target/python-venv) is made if missing, with maturin, pytest, numpy and mypy from PyPI;
# `FPPM_PYTHON` names the interpreter to make it with (default python3, which must be 3.11 or
# later). Fails when a test fails.
#
# `FPPM_BIN` names an fppm command already built to compare with (none: the release build of
# this checkout, built here); `FPPM_MODULE_PROFILE` the cargo profile of the module (default
# release, as `pip install` builds it). `.ci/run` gives its dev build of both.
set -euo pipefail
cd "$(dirname "$0")/../.."

venv=target/python-venv
python=${FPPM_PYTHON:-python3}
if [[ ! -x "$venv/bin/python" ]]; then
    echo "== creating $venv with $($python --version)"
    "$python" -c 'import sys; sys.exit(sys.version_info < (3, 11))' ||
        { echo "ci.sh: the fppm module needs Python 3.11 or later" >&2; exit 1; }
    "$python" -m venv "$venv"
fi
export PATH="$PWD/$venv/bin:$PATH" VIRTUAL_ENV="$PWD/$venv"
# Quick when they are there: pip does not ask the registry about what is installed.
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check maturin pytest numpy mypy

if [[ -z "${FPPM_BIN:-}" ]]; then
    echo "== cargo build --release -p cli (the command the tests compare with)"
    cargo build --release -p cli
    export FPPM_BIN="$PWD/target/release/fppm"
fi
echo "== the tests compare with $FPPM_BIN"
if [[ -n "${FPPM_MODULE_PROFILE:-}" ]]; then
    export MATURIN_PEP517_ARGS="--profile $FPPM_MODULE_PROFILE"
fi

echo "== pip install ./crates/python (maturin, ${FPPM_MODULE_PROFILE:-release})"
# The README's command, without build isolation: the venv's maturin builds, so that CI does not
# fetch maturin into a fresh environment for every run. The build shares target/<profile> with
# the command's when both are built in the same profile.
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-build-isolation \
    --force-reinstall --no-deps ./crates/python

echo "== pytest crates/python/tests"
"$venv/bin/python" -m pytest -q crates/python/tests

echo "== mypy stubtest fppm (the type stubs against the built module)"
"$venv/bin/python" -m mypy.stubtest fppm --allowlist crates/python/stubtest-allowlist.txt
