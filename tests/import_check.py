# tests/import_check.py - the Blender half of tests/import_check.sh: import
# each file the tool wrote with Blender's own importer, check that nothing
# is missing, and compare an unlit Cycles render with `tiledtex render
# --unlit` from the same viewpoint.
#
#   blender -b --factory-startup --python tests/import_check.py -- \
#       [--size N] [--samples N] [--limit L] [--control-min C] OUTDIR \
#       LABEL IMPORTER FILE REFERENCE.png [LABEL IMPORTER FILE REFERENCE.png ...]
#
# IMPORTER is gltf (bpy.ops.import_scene.gltf) or obj (bpy.ops.import_scene.obj,
# Blender 3.4's default OBJ importer); REFERENCE.png is `tiledtex render FILE
# TEXTURE REFERENCE.png --unlit --size NxN` (of the OBJ of the same result
# for a GLB: the tool's renderer reads no glTF). For each file it prints four
# lines, each "ok   ..." or "FAIL ...", which the shell script counts:
#   1. it imports, every material's base colour is an image that loaded;
#   2. the import has as many triangles as the file holds (tests/mesh_counts.py);
#   3. Blender's picture differs from REFERENCE.png by at most L/255 on average
#      (mean absolute difference of the RGB bytes) where both cover the model,
#      and both cover the same pixels;
#   4. a control that must differ: the same render with the texture
#      coordinates' v flipped scores above C/255, so 3 cannot pass by accident.
import math
import os
import sys

import bpy
import numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_glb  # noqa: E402  (found through the path set just above)
import mesh_counts  # noqa: E402

# `tiledtex render`'s background (examples/render.c, background_color): a
# vertical gradient of displayed greys, blue a little higher, drawn with 2x2
# supersampling. Pixels within this many bytes of it are background.
BACKGROUND_TOP, BACKGROUND_FALL, BACKGROUND_BLUE = 0.86, 0.16, 0.015
RENDER_SUPERSAMPLING = 2
BACKGROUND_TOLERANCE = 2
# Both renderers must cover nearly the same pixels: only the silhouette's
# anti-aliased edge may fall either way.
MIN_COVERAGE_AGREEMENT = 0.97


def parse_arguments(argv):
    args = argv[argv.index('--') + 1:] if '--' in argv else []
    options = {'size': 256, 'samples': 64, 'limit': 8.0, 'control-min': 16.0}
    positional = []
    i = 0
    while i < len(args):
        if args[i].startswith('--') and args[i][2:] in options and i + 1 < len(args):
            options[args[i][2:]] = type(options[args[i][2:]])(args[i + 1])
            i += 2
        else:
            positional.append(args[i])
            i += 1
    if not positional or (len(positional) - 1) % 4 != 0:
        sys.exit('usage: blender -b --factory-startup --python tests/import_check.py -- [options] OUTDIR '
                 'LABEL gltf|obj FILE REFERENCE.png ...')
    jobs = [positional[k:k + 4] for k in range(1, len(positional), 4)]
    return positional[0], jobs, options


def srgb_to_linear(c):
    return numpy.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(c):
    return numpy.where(c <= 0.0031308, c * 12.92, 1.055 * numpy.power(numpy.maximum(c, 0.0), 1 / 2.4) - 0.055)


def tool_background(width, height):
    """The tool's background as bytes, height x width x 3, row 0 at the top:
    each pixel averages its samples' rows in linear light, then encodes."""
    rows = numpy.arange(height * RENDER_SUPERSAMPLING, dtype=numpy.float64) / (height * RENDER_SUPERSAMPLING)
    grey = BACKGROUND_TOP - BACKGROUND_FALL * rows
    samples = numpy.stack([grey, grey, grey + BACKGROUND_BLUE], axis=1)
    linear = srgb_to_linear(samples).reshape(height, RENDER_SUPERSAMPLING, 3).mean(axis=1)
    encoded = numpy.round(linear_to_srgb(linear) * 255.0)
    return numpy.broadcast_to(encoded[:, None, :], (height, width, 3))


def load_bytes(path):
    """An 8-bit PNG as height x width x 4 floats in 0..255, row 0 at the top
    (Blender's pixels start at the bottom). Blender hands 8-bit images over
    as their stored bytes, whatever their colour space."""
    image = bpy.data.images.load(path)
    width, height = image.size
    pixels = numpy.empty(width * height * 4, dtype=numpy.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return numpy.round(pixels.reshape(height, width, 4)[::-1] * 255.0)


def compare(blender_png, reference_png):
    """(mean absolute difference in bytes over the pixels both cover fully,
    away from the silhouette; how many pixels that is; the share of the
    pixels either covers that both cover)."""
    ours = load_bytes(blender_png)
    theirs = load_bytes(reference_png)
    if ours.shape != theirs.shape:
        return math.inf, 0, 0.0
    height, width = ours.shape[:2]
    tool_covers = numpy.any(numpy.abs(theirs[:, :, :3] - tool_background(width, height)) > BACKGROUND_TOLERANCE, axis=2)
    blender_covers = ours[:, :, 3] >= 128
    solid = (ours[:, :, 3] == 255) & tool_covers
    # One pixel in from every edge of the solid region: the silhouette's
    # anti-aliasing is each renderer's own.
    interior = solid.copy()
    interior[1:, :] &= solid[:-1, :]
    interior[:-1, :] &= solid[1:, :]
    interior[:, 1:] &= solid[:, :-1]
    interior[:, :-1] &= solid[:, 1:]
    either = numpy.count_nonzero(tool_covers | blender_covers)
    agreement = numpy.count_nonzero(tool_covers & blender_covers) / either if either else 0.0
    count = int(numpy.count_nonzero(interior))
    if count == 0:
        return math.inf, 0, agreement
    difference = numpy.abs(ours[:, :, :3] - theirs[:, :, :3])[interior].mean()
    return float(difference), count, agreement


def import_file(importer, path):
    if importer == 'gltf':
        return bpy.ops.import_scene.gltf(filepath=path)
    # The MTL must name its textures where they are: no search of the folder.
    return bpy.ops.import_scene.obj(filepath=path, use_image_search=False)


def base_colour_nodes(meshes, path):
    """Every material's Image Texture node feeding its base colour, and a
    list of what is missing (a material without one, an image that did not
    load, or that was found outside the model's folder: Blender's OBJ
    importer also looks in the current directory)."""
    folder = os.path.dirname(os.path.abspath(path))
    nodes, missing = [], []
    for o in meshes:
        for slot in o.material_slots:
            material = slot.material
            bsdf = next((n for n in material.node_tree.nodes if n.type == 'BSDF_PRINCIPLED'), None) \
                if material and material.use_nodes else None
            node = blender_glb.linked_image_node(bsdf.inputs['Base Color']) if bsdf else None
            if node is None:
                missing.append(f"material {material.name if material else '(none)'} has no base-colour image")
                continue
            image = node.image
            if image.size[0] == 0:
                missing.append(f"image {image.name} ({image.filepath}) did not load")
                continue
            file = os.path.abspath(bpy.path.abspath(image.filepath))
            if image.packed_file is None and os.path.commonpath([folder, file]) != folder:
                missing.append(f"image {image.name} was read from {file}, outside {folder}")
                continue
            nodes.append((material, node))
    if not nodes and not missing:
        missing.append('no material')
    return nodes, missing


def make_unlit(material_nodes):
    """Each material shows its base-colour image as emission: the colour as
    it is, as `tiledtex render --unlit` draws it."""
    for material, image_node in material_nodes:
        tree = material.node_tree
        output = next((n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL' and n.is_active_output),
                      None) or tree.nodes.new('ShaderNodeOutputMaterial')
        emission = tree.nodes.new('ShaderNodeEmission')
        emission.inputs['Strength'].default_value = 1.0
        tree.links.new(image_node.outputs['Color'], emission.inputs['Color'])
        tree.links.new(emission.outputs['Emission'], output.inputs['Surface'])


def setup_render(meshes, options):
    scene = bpy.context.scene
    blender_glb.add_camera_like_render(meshes, {'yaw': 30.0, 'pitch': 20.0, 'up': 'y'}, options['size'],
                                       options['size'])
    blender_glb.use_cycles_on_cpu(scene, options['samples'], 0.0)
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.seed = 1
    # Emission seen straight from the camera: no bounce changes a pixel.
    scene.cycles.max_bounces = 0
    # A one-pixel box, as the tool averages its 2x2 samples: no blur across pixels.
    scene.cycles.pixel_filter_type = 'BOX'
    scene.cycles.filter_width = 1.0
    scene.render.film_transparent = True
    scene.render.resolution_x = scene.render.resolution_y = options['size']
    scene.render.resolution_percentage = 100
    # Plain sRGB and no dither noise, as the tool encodes its pictures.
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.dither_intensity = 0.0
    scene.render.image_settings.file_format = 'PNG'
    scene.render.image_settings.color_mode = 'RGBA'
    scene.render.image_settings.color_depth = '8'


def render_to(path):
    bpy.context.scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def flip_v(meshes):
    for o in meshes:
        for layer in o.data.uv_layers:
            uv = numpy.empty(2 * len(layer.data), dtype=numpy.float32)
            layer.data.foreach_get('uv', uv)
            uv[1::2] = 1.0 - uv[1::2]
            layer.data.foreach_set('uv', uv)


def report(ok, what):
    print(('ok   ' if ok else 'FAIL ') + what, flush=True)


def check_file(outdir, label, importer, path, reference, options):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    try:
        result = import_file(importer, path)
    except RuntimeError as error:
        result = {str(error).strip().splitlines()[-1]}
    meshes = [o for o in bpy.context.scene.objects if o.type == 'MESH']
    if 'FINISHED' not in result or not meshes:
        report(False, f"{label}: Blender could not import {path}: {', '.join(sorted(result))}")
        for what in ('triangle count', 'render', 'control'):
            report(False, f"{label}: {what}: not imported")
        return
    material_nodes, missing = base_colour_nodes(meshes, path)
    sizes = sorted({f"{node.image.size[0]}x{node.image.size[1]}" for _, node in material_nodes})
    report(not missing, f"{label}: imports from the moved folder with its base colour "
                        f"({', '.join(sizes) or 'none'})" + (f"; missing: {'; '.join(missing)}" if missing else ''))

    expected = mesh_counts.triangles(path)
    got = 0
    for o in meshes:
        o.data.calc_loop_triangles()
        got += len(o.data.loop_triangles)
    report(got == expected, f"{label}: {got} triangles imported, the file holds {expected}")

    if missing:
        for what in ('render', 'control'):
            report(False, f"{label}: {what}: no texture to draw")
        return
    make_unlit(material_nodes)
    setup_render(meshes, options)
    picture = os.path.join(outdir, f"{label.replace(' ', '_')}.png")
    render_to(picture)
    difference, pixels, agreement = compare(picture, reference)
    report(difference <= options['limit'] and agreement >= MIN_COVERAGE_AGREEMENT,
           f"{label}: unlit render differs from tiledtex render --unlit by {difference:.2f}/255 (limit "
           f"{options['limit']:g}) over {pixels} pixels; both cover {100 * agreement:.1f}% of the pixels either "
           f"covers (at least {100 * MIN_COVERAGE_AGREEMENT:g}%)")

    flip_v(meshes)
    control = os.path.join(outdir, f"{label.replace(' ', '_')}_v_flipped.png")
    render_to(control)
    difference, pixels, _ = compare(control, reference)
    report(difference > options['control-min'],
           f"{label}: control: with v flipped the render differs by {difference:.2f}/255 (must exceed "
           f"{options['control-min']:g}) over {pixels} pixels")


def main():
    outdir, jobs, options = parse_arguments(sys.argv)
    blender_glb.restore_numpy_bool()
    for label, importer, path, reference in jobs:
        check_file(outdir, label, importer, path, reference, options)


main()
