#!/usr/bin/env bash
# Builds the documentation site into target/docs/html: Sphinx (MyST Markdown) from docs/, the
# example gallery (every examples/plot_*.py executed), the Python API reference generated from
# python/fado and its stub, and the rustdoc of the three crates copied beside it (html/rust/).
# Warnings are errors. The pinned tools of docs/requirements.txt and the package itself are
# installed into .venv (created by scripts/test-all.sh, or here).
# Usage: bash scripts/docs.sh
set -euo pipefail
cd "$(dirname "$0")/.."

venv=.venv
if [[ ! -x "$venv/bin/python" ]]; then
    "${PYTHON:-python3}" -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import fado, matplotlib, pandas" >/dev/null 2>&1; then
    "$venv/bin/python" -m pip install --quiet '.[plot,pandas]'
fi
"$venv/bin/python" -m pip install --quiet -r docs/requirements.txt

target=${CARGO_TARGET_DIR:-target}
out="$target/docs"
echo "== rustdoc"
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps
echo "== sphinx"
rm -rf "$out/html" docs/auto_examples docs/reference/api
MPLBACKEND=Agg "$venv/bin/python" -m sphinx -W --keep-going -q -b html -d "$out/doctrees" docs "$out/html"
rm -rf "$out/html/rust"
cp -r "$target/doc" "$out/html/rust"
echo "documentation: $out/html/index.html"
