#!/usr/bin/env bash
# Runs every test of the project: the Rust workspace (release mode, as CI does), then, when the
# Python package exists, its tests in a virtual environment at .venv (created or refreshed here,
# so that a fresh machine needs only Rust and Python 3).
set -euo pipefail
cd "$(dirname "$0")/.."

cargo test --workspace --release

if [[ ! -f pyproject.toml ]]; then
    echo "no pyproject.toml: Python tests skipped"
    exit 0
fi

python=${PYTHON:-python3}
venv=.venv
# A venv whose interpreter vanished (Python upgraded, pyenv switched) is rebuilt.
if [[ -d "$venv" ]] && ! "$venv/bin/python" -c "import sys" >/dev/null 2>&1; then
    echo "rebuilding broken $venv"
    rm -rf "$venv"
fi
if [[ ! -d "$venv" ]]; then
    if ! "$python" -m venv "$venv"; then
        # Debian's python3 without python3-venv: fall back to virtualenv.
        rm -rf "$venv"
        "$python" -m pip install --quiet --user virtualenv
        "$python" -m virtualenv --quiet "$venv"
    fi
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip || echo "pip upgrade failed (offline?): keeping the venv's pip"
# Builds the extension through its maturin build backend (pip fetches maturin as needed).
"$venv/bin/python" -m pip install --quiet '.[plot,pandas,test]'

if [[ ! -d tests/python ]]; then
    echo "no tests/python: Python tests skipped"
    exit 0
fi
status=0
"$venv/bin/python" -m pytest tests/python -q || status=$?
if [[ $status -eq 5 ]]; then
    # pytest's "no tests collected": nothing failed, but say so loudly.
    echo "WARNING: tests/python holds no tests"
    exit 0
fi
exit $status
