#!/bin/bash
# Installs everything SDFCage needs on Debian 12 (bookworm), as root.
#   bash .ci/setup.sh           build + the command-line program (with --screenshot)
#   bash .ci/setup.sh --tests   the same plus what the test suite needs
# This is the one place the package list lives; README.md shows the commands that call it.
set -euo pipefail

# Verified on a clean Debian 12 root (../shared/tools/fresh-machine/fresh.sh):
#  - cmake ... xauth: ParaView 5.11 (its own VTK 9.2) + OpenVDB + Eigen + TBB; ParaView's CMake
#    config also needs the MPI headers and double-conversion; xvfb-run needs xauth.
#  - libglew-dev libfreetype-dev libx11-dev: VTK's OpenGL rendering and text for the program's
#    --screenshot (ParaView's VTK links them through imported targets that only exist with the
#    -dev packages).
#  - libcgal-dev libgtest-dev: exact-predicate cross-checks and unit tests (tests only).
#  - tetgen: the test that TetGen meshes the space between a cage and its input (tests only).
#  - clang libclang-rt-14-dev: libFuzzer and the sanitizers' runtimes for .ci/fuzz.sh (tests only).
packages=(
  cmake ninja-build g++ ccache
  libeigen3-dev libtbb-dev libopenvdb-dev libboost-iostreams-dev
  libopenmpi-dev libdouble-conversion-dev paraview-dev python3-paraview
  libglew-dev libfreetype-dev libx11-dev
  xvfb xauth
)
test_packages=(libcgal-dev libgtest-dev tetgen clang libclang-rt-14-dev)

case "${1:-}" in
  "") ;;
  --tests) packages+=("${test_packages[@]}") ;;
  *) echo "usage: $0 [--tests]" >&2; exit 2 ;;
esac

sudo=()
if [ "$(id -u)" != 0 ]; then
  sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update
"${sudo[@]}" apt-get install -y --no-install-recommends "${packages[@]}"
