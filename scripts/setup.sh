#!/usr/bin/env bash
# Set up speclight on a fresh machine: system libraries (when root and apt are available),
# a virtual environment in .venv and the package with its pinned dependency ranges.
#   bash scripts/setup.sh          # the package and all its engines
#   bash scripts/setup.sh --dev    # ... plus the test and lint tools
# Re-running is cheap: nothing is reinstalled unless pyproject.toml changed.
set -euo pipefail
cd "$(dirname "$0")/.."

extras="all"
[[ "${1:-}" == "--dev" ]] && extras="all,dev"

# System libraries: libLLVM-19 for Mitsuba's fast LLVM backend, libgfortran5 for 6S; apt-get
# runs only for what is missing (see scripts/system_libs.sh for how they are found).
# shellcheck source=scripts/system_libs.sh
source scripts/system_libs.sh
install_system_libs

python=${PYTHON:-python3}
"$python" -c 'import sys; sys.exit(sys.version_info < (3, 11))' || {
    echo "setup: speclight needs Python 3.11 or newer ($python is $("$python" -V 2>&1))" >&2
    exit 1
}
[[ -x .venv/bin/python ]] || "$python" -m venv .venv

stamp=.venv/.speclight-installed
want="$extras $(sha256sum pyproject.toml | cut -c1-16)"
if [[ ! -f $stamp || "$(cat "$stamp")" != "$want" ]]; then
    echo "setup: installing speclight[$extras] into .venv (first time takes a few minutes)" >&2
    .venv/bin/python -m pip install -q --disable-pip-version-check --upgrade pip >/dev/null
    .venv/bin/python -m pip install -q --disable-pip-version-check -e ".[$extras]"
    if [[ $extras == *dev* ]]; then
        # lumos-sat, a test oracle only (tests/target/test_brdf_forms_lumos.py): its pins
        # (numpy~=1.24, astropy~=5.2) conflict with ours; the BRDF functions used need numpy only
        .venv/bin/python -m pip install -q --disable-pip-version-check --no-deps "lumos-sat==1.0.9"
    fi
    echo "$want" >"$stamp"
fi
