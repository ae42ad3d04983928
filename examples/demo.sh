#!/usr/bin/env bash
# `make demo`: the whole pipeline on inputs made from nothing.
#
#   1. a procedural stone texture and the rest of its material (normal, height, roughness, ao):
#                                           build/demo/texture.png, texture_normal.png, ...
#   2. a smooth double torus (genus 2)      build/demo/double_torus_mesh.obj
#   3. tiled textures (Akleman et al.):     build/demo/double_torus.obj/.mtl/.png, and an atlas
#                                           per map (double_torus_normal.png, ...); the same as one
#                                           binary glTF file: build/demo/double_torus.glb
#   4. pictures of the result               build/demo/double_torus_front.png, _side.png, _closeup.png,
#                                           _relief.png (lit through the normal map)
#   5. lapped textures (Praun et al.) on the same surface, runtime pasting and baked:
#                                           build/demo/lapped.obj/.mtl, lapped_patch_1..4.png, lapped_baked.*,
#                                           pictures build/demo/lapped_front.png, lapped_baked_front.png
#   6. hierarchical pattern mapping (Soler et al.): texture coordinates into the texture itself:
#                                           build/demo/hpm.obj/.mtl/.png, picture build/demo/hpm_front.png
#   7. polycube + Wang tiles (Chang and Lin): the triangles split along a polycube's squares:
#                                           build/demo/polycube.obj/.mtl/.png, polycube_polycube.obj,
#                                           pictures build/demo/polycube_front.png, polycube_cubes.png
set -euo pipefail
cd "$(dirname "$0")/.."

tool=build/tiledtex
out=build/demo
if [ ! -x "$tool" ]; then
    echo "demo: $tool is missing; run 'make' first" >&2
    exit 1
fi
mkdir -p "$out"

"$tool" generate texture "$out/texture.png" --size 512 --seed 1 --material
"$tool" generate mesh "$out/double_torus_mesh.obj" --shape double-torus
# The material's maps share the colour's tiles: one plan, every map cut alike.
maps=(--normal "$out/texture_normal.png" --height "$out/texture_height.png"
      --roughness "$out/texture_roughness.png" --ao "$out/texture_ao.png")
"$tool" tile "$out/double_torus_mesh.obj" "$out/texture.png" "$out/double_torus" "${maps[@]}"
"$tool" tile "$out/double_torus_mesh.obj" "$out/texture.png" "$out/double_torus.glb" "${maps[@]}"
"$tool" render "$out/double_torus.obj" "$out/double_torus.png" "$out/double_torus_front.png" --yaw 20 --pitch 15
"$tool" render "$out/double_torus.obj" "$out/double_torus.png" "$out/double_torus_side.png" --yaw -40 --pitch 55
"$tool" render "$out/double_torus.obj" "$out/double_torus.png" "$out/double_torus_closeup.png" \
    --yaw 10 --pitch 30 --zoom 3 --size 900x600 --wireframe
"$tool" render "$out/double_torus.obj" "$out/double_torus.png" "$out/double_torus_relief.png" \
    --yaw 10 --pitch 30 --zoom 3 --size 900x600 --normal "$out/double_torus_normal.png"
"$tool" lapped "$out/double_torus_mesh.obj" "$out/texture.png" "$out/lapped" --scale 1.2 --seed 1 --pasting --bake 2048
# Four patches (windows of the 512x512 texture): render takes each paste's from its material.
"$tool" render "$out/lapped.obj" "$out/lapped_patch_1.png" "$out/lapped_front.png" --yaw 20 --pitch 15
"$tool" render "$out/lapped_baked.obj" "$out/lapped_baked.png" "$out/lapped_baked_front.png" --yaw 20 --pitch 15
# The texture's width spans 3 of the surface's 5.7 units: stones large enough to see where clusters meet.
"$tool" hpm "$out/double_torus_mesh.obj" "$out/texture.png" "$out/hpm" --scale 3 --seed 1
"$tool" render "$out/hpm.obj" "$out/texture.png" "$out/hpm_front.png" --yaw 20 --pitch 15
"$tool" polycube "$out/double_torus_mesh.obj" "$out/texture.png" "$out/polycube" --seed 1
"$tool" render "$out/polycube.obj" "$out/polycube.png" "$out/polycube_front.png" --yaw 20 --pitch 15
"$tool" render "$out/polycube_polycube.obj" "$out/polycube.png" "$out/polycube_cubes.png" --yaw 20 --pitch 15

echo
echo "pictures:"
echo "  $out/texture.png               the example image"
echo "  $out/double_torus.png          the tile atlas made from it"
echo "  $out/double_torus_front.png    the textured double torus"
echo "  $out/double_torus_side.png     the same from another side"
echo "  $out/double_torus_closeup.png  close up, with the quads drawn: the stones run across every edge"
echo "  $out/double_torus_relief.png   the same lit through the normal atlas: the stones stand out"
echo "  $out/double_torus.glb          the textured double torus with its whole material, for Blender or an engine"
echo "  $out/lapped_front.png          lapped textures: overlapping pastes of one patch, drawn in order"
echo "  $out/lapped_baked_front.png    the same pastes baked into one texture over an atlas of triangle pairs"
echo "  $out/hpm_front.png             hierarchical pattern mapping: patches of the example image itself, fitted to their neighbours"
echo "  $out/polycube_front.png        polycube + Wang tiles: the surface carries the tiles of the polycube around it"
echo "  $out/polycube_cubes.png        that polycube, each square one tile"
