#!/usr/bin/env bash
# Installs what snede needs and nothing else; a second run finishes in seconds.
# Usage: bash tools/setup.sh   (root, or a user with sudo; no questions asked)
set -euo pipefail
cd "$(dirname "$0")/.."

APT_PACKAGES=(
  petsc-dev libptscotch-dev libhdf5-openmpi-dev libeigen3-dev libcgal-dev pkg-config ninja-build libgtest-dev
  # system libraries the gmsh and VTK wheels load
  libglu1-mesa libxcursor1 libxft2 libxinerama1 libegl1 libgl1-mesa-dri
  # the display the live window's tests start (python -m snede view; VTK renders through Mesa's GLX on it)
  xvfb
)
PETSC_DIR_DEBIAN=/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real
PYTHON=${PYTHON:-python3}

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -q
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

if [ ! -x .venv/bin/python ]; then
  echo "setup: creating .venv with $($PYTHON --version)"
  "$PYTHON" -m venv .venv
fi
PIP=".venv/bin/python -m pip --disable-pip-version-check -q"

stamp=.venv/.snede-requirements
if ! cmp -s tools/requirements.txt "$stamp"; then
  echo "setup: installing Python packages (first time: about 5 minutes, petsc4py and mpi4py compile)"
  $PIP install -r tools/build-requirements.txt
  # mpi4py and petsc4py must be built against Debian's OpenMPI and PETSc, not taken as wheels.
  PETSC_DIR=$PETSC_DIR_DEBIAN MPICC=mpicc $PIP install --no-build-isolation \
      --no-binary mpi4py,petsc4py -r tools/requirements.txt
  cp tools/requirements.txt "$stamp"
fi

# snede itself: rebuilt by scikit-build-core only when sources changed (build dir is kept).
# SNEDE_NATIVE=OFF builds for the x86-64 baseline instead of this processor, in a build
# directory of its own, so that switching back and forth rebuilds nothing.
source tools/build_mode.sh
echo "setup: building snede (SNEDE_NATIVE=$SNEDE_NATIVE)"
PETSC_DIR=$PETSC_DIR_DEBIAN $PIP install --no-build-isolation --no-deps -e . \
    -Cbuild-dir="build/python$BUILD_SUFFIX" -Ccmake.define.SNEDE_NATIVE="$SNEDE_NATIVE"
echo "setup: done"
