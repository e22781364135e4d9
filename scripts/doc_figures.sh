#!/bin/sh
# Regenerates the figures of docs/analytic-pipeline.md and docs/workbench.md (each page shows
# the command under its picture). Usage: scripts/doc_figures.sh [path/to/penumbra]
set -e
P=${1:-target/release/penumbra}
D=docs/images/figures
mkdir -p $D
# docs/analytic-pipeline.md, "In pictures": one floor point of the default scene, stage by stage.
AT="--size 320x240 --pixel 160,173 --figure-size 480"
$P figure default $AT --view sphere --stage 1 --out $D/pipeline_1_silhouette.svg
$P figure default $AT --view sphere --stage 5 --out $D/pipeline_5_occluder.svg
$P figure default $AT --view plane --stage 7 --out $D/pipeline_7_gh_intersections.svg
$P figure default $AT --view plane --stage 8 --out $D/pipeline_8_gh_labels.svg
$P figure default $AT --view plane --stage 9 --out $D/pipeline_9_gh_traversal.svg
$P figure default $AT --view sphere --stage 10 --out $D/pipeline_10_visible.svg
$P figure default $AT --view hemisphere --stage 10 --out $D/pipeline_10_nusselt.svg
# docs/workbench.md: the views of the picked point.
$P figure default --size 320x240 --pixel 160,173 --view sphere --out $D/sphere_view.svg
$P figure default --size 320x240 --pixel 160,173 --view plane --stage 9 --out $D/gh_step.svg
$P figure polyhedra --size 320x240 --pixel 160,204 --view sphere --stage 76 \
  --out $D/nonconvex_silhouette.svg
$P figure env_figures --env-method rt --size 320x240 --pixel 134,204 --view environment \
  --out $D/environment.svg
$P figure polyhedra --size 320x240 --pixel 160,204 --view bsp --light hole --out $D/bsp_planes.svg
$P figure nonconvex --size 320x240 --pixel 144,180 --view light --light u_light \
  --out $D/bsp_cell.svg
