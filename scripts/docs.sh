#!/usr/bin/env bash
# Builds the manual (docs/, Sphinx with MyST Markdown) into build/docs/html with warnings as errors,
# then checks its links, paths and reach (scripts/check_docs.py). Needs the build (scripts/build.sh):
# the command-line reference shows the programs' --help and the Python reference imports femb.
set -euo pipefail
cd "$(dirname "$0")/.."
dpkg-query -W -f='${Status}' python3-sphinx python3-myst-parser 2>/dev/null | grep -q "install ok installed" \
  || bash scripts/setup.sh > /dev/null
export FEMB_BIN=${FEMB_BIN:-$PWD/build/bin}
export PYTHONPATH=${FEMB_PYTHONPATH:-$PWD/build/python}${PYTHONPATH:+:$PYTHONPATH}
out=${1:-build/docs}
/usr/bin/python3 -m sphinx -W --keep-going -n -q -b html -d "$out/doctrees" docs "$out/html"
/usr/bin/python3 scripts/check_docs.py --bin "$FEMB_BIN"
echo "docs: $out/html/index.html"
