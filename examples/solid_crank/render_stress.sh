#!/usr/bin/env bash
# The crank's stress picture: reduce the solid crank (run.sh's part file), solve the
# static side load of stress_scene.yaml with stress recovery, compare the web's recovered stress
# with beam theory, and render von Mises on the deformed mesh with ParaView (pvpython under
# xvfb-run) into docs/results/solid_crank_von_mises.png. Installs paraview and xvfb (Debian) when
# missing: they are not part of the default set-up.
# Usage: bash examples/solid_crank/render_stress.sh [BUILD_BIN_DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${1:-$here/../../build/bin}
out=$here/out
mkdir -p "$out"
# ParaView's Python (Debian: python3-paraview).
find_pv() { command -v pvpython; }
if [ -z "$(find_pv)" ] || ! command -v xvfb-run > /dev/null; then
  sudo_cmd=""; [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends paraview python3-paraview xvfb xauth
fi
[ -s "$out/solid_crank.h5" ] || "$bin/femb-reduce" -q "$here/part.yaml" -o "$out/solid_crank.h5"
"$bin/femb-solve" -q "$here/stress_scene.yaml" -o "$out/stress"
/usr/bin/python3 - "$out/stress/probes.csv" <<'PY'
import csv, sys
row = list(csv.DictReader(open(sys.argv[1])))[-1]
sxx, ref = float(row["web_side.stress.xx"]), -1000 * 0.075 * 0.012 / (0.012 * 0.024 ** 3 / 12)
print(f"web side at mid-length: sigma_xx {sxx / 1e6:.2f} MPa, beam theory {ref / 1e6:.2f} MPa ({100 * (sxx / ref - 1):+.1f}%)")
PY
png=$here/../../docs/results/solid_crank_von_mises.png
xvfb-run -a "$(find_pv)" "$here/render_stress.py" "$out/stress/animation.xdmf" "$png" 100
