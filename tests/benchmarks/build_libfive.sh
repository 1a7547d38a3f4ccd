#!/bin/sh
# Build libfive (https://github.com/libfive/libfive), the peer of bench_mesh_out.py,
# outside the repository: its C library and its Python bindings (ctypes), nothing else
# (no Studio, no Guile).
#
#   sh tests/benchmarks/build_libfive.sh [SOURCE]
#
# SOURCE: a libfive checkout (default: a shallow clone of its main branch). Everything
# goes to $LIBFIVE_HOME (default ~/.cache/implicitvox/libfive): bench_mesh_out.py looks
# there (or in $LIBFIVE_HOME) for lib/libfive.so, lib/libfive-stdlib.so and python/.
# Needs cmake, a C++17 compiler, Eigen 3, Boost headers and libpng; on Debian:
#   apt-get install cmake g++ libeigen3-dev libboost-dev libpng-dev pkg-config
set -eu
HOME_DIR=${LIBFIVE_HOME:-$HOME/.cache/implicitvox/libfive}
SOURCE=${1:-$HOME_DIR/src}
if [ ! -d "$SOURCE/libfive" ]; then
    git clone --depth 1 https://github.com/libfive/libfive "$SOURCE"
fi
cmake -S "$SOURCE" -B "$HOME_DIR/build" -DCMAKE_BUILD_TYPE=Release -DENABLE_DEBUG=OFF \
      -DBUILD_STUDIO_APP=OFF -DBUILD_GUILE_BINDINGS=OFF -DBUILD_PYTHON_BINDINGS=OFF
cmake --build "$HOME_DIR/build" --parallel 2 --target libfive libfive-stdlib
mkdir -p "$HOME_DIR/lib" "$HOME_DIR/python"
cp "$HOME_DIR/build/libfive/src/libfive.so" "$HOME_DIR/build/libfive/stdlib/libfive-stdlib.so" \
   "$HOME_DIR/lib/"
cp -r "$SOURCE/libfive/bind/python/libfive" "$HOME_DIR/python/"
echo "libfive built in $HOME_DIR"
