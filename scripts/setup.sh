#!/usr/bin/env bash
# Installs femb's build dependencies from Debian packages (safe to run twice) and checks that the
# BLAS CHOLMOD will use is OpenBLAS, not the reference BLAS (8-9x slower). Packages given as
# arguments are installed too (scripts/sanitizer_tree.sh: clang for the sanitizer tree). PETSc,
# SLEPc, MUMPS and OpenMPI are for femb-reduce on MPI ranks (reduction.solver: petsc).
set -euo pipefail
packages=(cmake g++ make pkg-config libeigen3-dev libspectra-dev libsuitesparse-dev libmetis-dev
  libhdf5-dev zlib1g-dev libgmsh-dev gmsh libyaml-cpp-dev nlohmann-json3-dev libgtest-dev libopenblas-dev
  python3-dev pybind11-dev python3-pytest python3-yaml python3-distributed python3-h5py python3-numpy python3-scipy python3-meshio python3-matplotlib python3-sphinx python3-myst-parser calculix-ccx
  petsc-dev slepc-dev libmumps-dev openmpi-bin "$@")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "setup: all ${#packages[@]} Debian packages present"
fi
blas=$(readlink -f /usr/lib/x86_64-linux-gnu/libblas.so.3 2>/dev/null || true)
case "$blas" in
  *openblas*) echo "setup: libblas.so.3 -> $blas (OpenBLAS)";;
  *) echo "setup: WARNING: libblas.so.3 -> $blas is not OpenBLAS; CHOLMOD will be 8-9x slower." \
          "Run: update-alternatives --set libblas.so.3-x86_64-linux-gnu" \
          "/usr/lib/x86_64-linux-gnu/openblas-pthread/libblas.so.3";;
esac
