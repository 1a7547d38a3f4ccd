#!/bin/sh
# Regenerate the .csg and .stl fixtures from the .scad models with the real OpenSCAD
# (Debian package openscad; these were made with OpenSCAD 2021.01). CI does not need it.
set -e
cd "$(dirname "$0")"
for f in *.scad; do
    openscad -q -o "${f%.scad}.csg" "$f"
    openscad -q -o "${f%.scad}.stl" "$f"
done
