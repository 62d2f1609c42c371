#!/usr/bin/env bash
# Regenerates every picture README.md and docs/ show (docs/images/*.png) from a built tree, with
# the skeleton and point-cloud code of that tree: rerun it after the skeleton or the renderer
# changes. Needs a Vulkan device (lavapipe will do) and CGAL's data set (Debian libcgal-dev).
#
#   scripts/make-figures.sh [BUILD_DIR]        # default ./build; writes docs/images/
#
# Pictures:
#   skeleton_tube.png       builtin:tube (the paper's Figure 7 model) and its skeleton
#   skeleton_man.png        CGAL's man.off (a human)
#   skeleton_camel.png      CGAL's camel.off (a quadruped)
#   skeleton_elephant.png   CGAL's elephant.off (genus 3: three cycles)
#   skeleton_armadillo.png  CGAL's armadillo.off (a humanoid: curves down every limb, no sheet)
#   skeleton_boeing.png     CGAL's boeing.off (a thin-walled rib: sheets on its flanges, the
#                           one mesh of the data set judged sheet-like besides the C and S plates)
#   worm_frame.png          frame 50 of the Sibernetic worm (tests/data/worm): its surface points
#                           and the 16-segment polyline of `sdfkit pointcloud-skeleton`
#   worm_strip.png          6 frames of the worm with their polylines side by side (Figure 15)
#   worm_compressed_strip.png  the same 6 frames of `sdfkit compress-animation`'s 16-bone glb,
#                           played back as a glTF viewer does (all 2290 particles)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${1:-build}"
SDFKIT="$BUILD/apps/sdfkit"
OUT=docs/images
CGAL_DATA="${CGAL_DATA:-/usr/share/doc/libcgal-dev/data.tar.gz}"
WORM=tests/data/worm
[ -x "$SDFKIT" ] || { echo "make-figures.sh: $SDFKIT not found (build first: scripts/build.sh)" >&2; exit 1; }
[ -f "$CGAL_DATA" ] || { echo "make-figures.sh: $CGAL_DATA not found (apt-get install libcgal-dev)" >&2; exit 1; }
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$OUT"
tar -xzf "$CGAL_DATA" -C "$WORK" --strip-components=2 data/meshes/man.off data/meshes/camel.off data/meshes/elephant.off \
  data/meshes/armadillo.off data/meshes/boeing.off

# Skeletons: `sdfkit skeleton`, then the mesh (SDF colours, faded) with curves, sheets, branch
# nodes and leaves in their own colours; the longest axis up (OFF files say nothing about up).
skeleton_picture() {
  local name="$1" mesh="$2"
  shift 2
  "$SDFKIT" skeleton "$mesh" -o "$WORK/$name.json" -q
  "$SDFKIT" render "$mesh" --skeleton "$WORK/$name.json" --views 3 --no-histogram --width 1500 --height 800 \
    -o "$OUT/skeleton_$name.png" "$@"
}
skeleton_picture tube builtin:tube
skeleton_picture man "$WORK/man.off"
# The camel's z extent beats its y by 2 %: the rule would lay it on its side; its file is +y up.
skeleton_picture camel "$WORK/camel.off" --up y
skeleton_picture elephant "$WORK/elephant.off"
skeleton_picture armadillo "$WORK/armadillo.off"
skeleton_picture boeing "$WORK/boeing.off"

# The worm: polylines of all 100 frames (the same end first in every frame), one frame, a strip.
"$SDFKIT" pointcloud-skeleton "$WORM" -o "$WORK/worm.json" --segments 16
"$SDFKIT" render "$WORM" --skeleton "$WORK/worm.json" --frame 50 --width 500 --height 800 -o "$OUT/worm_frame.png"
"$SDFKIT" render "$WORM" --skeleton "$WORK/worm.json" --strip 6 --width 1500 --height 700 -o "$OUT/worm_strip.png"

# The compressed animation, played back from the glb (points only: the glb carries no polyline).
"$SDFKIT" compress-animation "$WORM" -o "$WORK/worm.glb" --bones 16 --json "$WORK/worm_report.json"
"$SDFKIT" render "$WORK/worm.glb" --strip 6 --width 1500 --height 700 -o "$OUT/worm_compressed_strip.png"
echo "make-figures.sh: wrote $(ls "$OUT"/*.png | wc -l) pictures in $OUT"
