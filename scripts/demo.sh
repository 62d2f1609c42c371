#!/usr/bin/env bash
# The main job on the bundled default: installs dependencies, builds, and computes the SDF of
# the paper's Figure 7 model (a tube swept along a Bezier curve, diameter 2 -> 20) and of CGAL's
# elephant, writing glTF files with the _SDF attribute and SDF colours into ./out.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
mkdir -p out
./build/apps/sdfkit devices
./build/apps/sdfkit compute builtin:tube -o out/tube_sdf.glb --json out/tube_sdf.json
tar -xzf /usr/share/doc/libcgal-dev/data.tar.gz -C out --strip-components=2 data/meshes/elephant.off
./build/apps/sdfkit compute out/elephant.off -o out/elephant_sdf.glb --smooth 2
echo "wrote out/tube_sdf.glb and out/elephant_sdf.glb"
