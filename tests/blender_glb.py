# tests/blender_glb.py - open a GLB the tool wrote in Blender, say what the
# importer made of it, and optionally render it with Cycles on the CPU from
# the viewpoint `tiledtex render` uses, to compare the two pictures by eye.
#
#   blender -b --factory-startup --python tests/blender_glb.py -- FILE.glb [OUT.png]
#           [--yaw DEG] [--pitch DEG] [--up y|z] [--size N] [--samples N] [--obj FILE.obj]
#
# Prints one line "blender: ..." with the objects, vertices, triangles, UV
# layers, whether the faces are smooth with custom normals, and which image
# feeds each input of the material (base colour, normal, roughness,
# metallic, occlusion); exits 1 when the import fails or the mesh has no UV
# layer or no base-colour image. With --obj (the OBJ the same command wrote
# for the same result) it also checks that Blender reads the OBJ's texture
# coordinates at the OBJ's positions, corner for corner: v flipped right.
# Not part of `make test` itself (Blender is large and slow to start); see
# README.md, "glTF output". tests/import_check.py, which is, imports its
# helpers: the numpy fix, the image feeding a material input and the camera
# of `tiledtex render`.
import math
import struct
import sys

import bpy
from mathutils import Matrix, Vector


def parse_arguments(argv):
    args = argv[argv.index('--') + 1:] if '--' in argv else []
    options = {'yaw': 30.0, 'pitch': 20.0, 'up': 'y', 'size': 512, 'samples': 32, 'obj': ''}
    positional = []
    i = 0
    while i < len(args):
        name = args[i]
        if name.startswith('--') and name[2:] in options:
            kind = type(options[name[2:]])
            options[name[2:]] = kind(args[i + 1])
            i += 2
        else:
            positional.append(name)
            i += 1
    if not positional:
        sys.exit('usage: blender -b --python tests/blender_glb.py -- FILE.glb [OUT.png] [options]')
    return positional[0], positional[1] if len(positional) > 1 else None, options


def linked_image_node(socket):
    """The Image Texture node feeding a material input, through a Normal Map
    or Separate RGB/Color node if there is one, or None."""
    for link in socket.links:
        node = link.from_node
        if node.type == 'TEX_IMAGE' and node.image:
            return node
        for inner in node.inputs:
            found = linked_image_node(inner)
            if found:
                return found
    return None


def linked_image(socket):
    """The image feeding a material input, or None."""
    node = linked_image_node(socket)
    return node.image if node else None


def describe(objects):
    meshes = [o for o in objects if o.type == 'MESH']
    parts = []
    ok = bool(meshes)
    for o in meshes:
        mesh = o.data
        mesh.calc_loop_triangles()
        smooth = sum(p.use_smooth for p in mesh.polygons)
        parts.append(f"object {o.name}: {len(mesh.vertices)} vertices, {len(mesh.loop_triangles)} triangles, "
                     f"UV layers {[uv.name for uv in mesh.uv_layers]}, {smooth} of {len(mesh.polygons)} faces "
                     f"smooth, custom normals {mesh.has_custom_normals}")
        if not mesh.uv_layers:
            ok = False
        for slot in o.material_slots:
            material = slot.material
            bsdf = next((n for n in material.node_tree.nodes if n.type == 'BSDF_PRINCIPLED'), None)
            if bsdf is None:
                parts.append(f"material {material.name}: no Principled BSDF")
                ok = False
                continue
            inputs = {}
            for label, socket in (('base colour', 'Base Color'), ('normal', 'Normal'), ('roughness', 'Roughness'),
                                  ('metallic', 'Metallic')):
                image = linked_image(bsdf.inputs[socket])
                inputs[label] = f"{image.size[0]}x{image.size[1]} {image.colorspace_settings.name}" if image else None
            # The importer puts the occlusion texture into a node group of its
            # own ("glTF Settings", or "glTF Material Output" in newer Blenders).
            occlusion = [n for n in material.node_tree.nodes if n.type == 'GROUP' and 'glTF' in n.node_tree.name]
            inputs['occlusion'] = next((f"{img.size[0]}x{img.size[1]}" for group in occlusion
                                        for socket in group.inputs for img in [linked_image(socket)] if img), None)
            parts.append(f"material {material.name}: " + ", ".join(f"{k} {v}" for k, v in inputs.items()) +
                         f", backface culling {material.use_backface_culling}")
            if not inputs['base colour']:
                ok = False
    print('blender: ' + '; '.join(parts) if parts else 'blender: no mesh imported')
    return ok, meshes


def float32(x):
    return struct.unpack('f', struct.pack('f', x))[0]


def compare_with_obj(meshes, path):
    """Does Blender read, at every face corner, the position and texture
    coordinate the tool's OBJ of the same result has? Both are taken as sets
    of (position, uv) pairs: the OBJ's faces may be quads where the GLB has
    triangles. Positions must be the same floats (the OBJ's 9 digits read
    back exactly), in the OBJ's frame: the importer turned glTF's (x, y, z)
    into Blender's (x, -z, y). Texture coordinates may differ by rounding:
    v is flipped once on writing and once on importing."""
    positions, uvs, obj_corners = [], [], set()
    with open(path) as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            if words[0] == 'v':
                positions.append(tuple(float32(float(x)) for x in words[1:4]))
            elif words[0] == 'vt':
                uvs.append(tuple(float(x) for x in words[1:3]))
            elif words[0] == 'f':
                for corner in words[1:]:
                    v, vt = corner.split('/')[:2]
                    obj_corners.add((positions[int(v) - 1], uvs[int(vt) - 1]))
    imported = {}
    for o in meshes:
        mesh = o.data
        layer = mesh.uv_layers.active.data
        for loop in mesh.loops:
            x, y, z = o.matrix_world @ mesh.vertices[loop.vertex_index].co
            imported.setdefault((x, z, -y), []).append(tuple(layer[loop.index].uv))
    found = sum(any(abs(u - a) < 1e-5 and abs(v - b) < 1e-5 for a, b in imported.get(position, []))
                for position, (u, v) in obj_corners)
    print(f"blender: {found} of {len(obj_corners)} distinct (position, uv) corners of {path} are in the import")
    return found == len(obj_corners)


def use_cycles_on_cpu(scene, samples, world_grey):
    """Cycles on the CPU, no denoising, `samples` per pixel, over a plain grey world."""
    world = bpy.data.worlds.new('world')
    world.color = (world_grey, world_grey, world_grey)
    scene.world = world
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False


def add_camera_like_render(meshes, options, width, height):
    """A camera where `tiledtex render` puts its own: around the bounding
    box's centre, yaw about the up axis and pitch above it, far enough that
    the bounding sphere fits a 35-degree view (along the picture's shorter
    side) with 10 % room. Returns the camera object and the picture's up and
    right as Blender vectors."""
    scene = bpy.context.scene
    corners = [o.matrix_world @ v.co for o in meshes for v in o.data.vertices]
    lo = Vector([min(c[k] for c in corners) for k in range(3)])
    hi = Vector([max(c[k] for c in corners) for k in range(3)])
    centre = (lo + hi) / 2
    radius = max((c - centre).length for c in corners) or 1.0
    # The importer turns glTF's y-up into Blender's z-up: glTF (x, y, z) is
    # Blender (x, -z, y). tiledtex render's frame: y up looks from +z with +x
    # to the right; z up looks from -y.
    to_blender = lambda x, y, z: Vector((x, -z, y))
    if options['up'] == 'z':
        up, front, side = to_blender(0, 0, 1), to_blender(0, -1, 0), to_blender(1, 0, 0)
    else:
        up, front, side = to_blender(0, 1, 0), to_blender(0, 0, 1), to_blender(1, 0, 0)
    yaw, pitch = math.radians(options['yaw']), math.radians(options['pitch'])
    toward_eye = side * (math.cos(pitch) * math.sin(yaw)) + up * math.sin(pitch) + front * (math.cos(pitch) * math.cos(yaw))
    half_fov = math.radians(35.0) / 2
    camera_data = bpy.data.cameras.new('camera')
    # The tool's field of view is along the shorter side; Blender's angle is
    # along the side sensor_fit names.
    camera_data.sensor_fit = 'HORIZONTAL' if width <= height else 'VERTICAL'
    camera_data.angle = 2 * half_fov
    camera = bpy.data.objects.new('camera', camera_data)
    scene.collection.objects.link(camera)
    distance = 1.1 * radius / math.sin(half_fov)
    camera.location = centre + toward_eye * distance
    # Blender clips at 0.1 and 100 units: a CAD part in millimetres is larger.
    camera_data.clip_start = 0.01 * radius
    camera_data.clip_end = distance + 2 * radius
    # Looking along -toward_eye with the model's up as the picture's up, as
    # the tool's camera does: Blender's camera looks down its -Z with +Y up.
    forward = -toward_eye.normalized()
    right = forward.cross(up).normalized()
    camera.rotation_euler = Matrix((right, right.cross(forward), -forward)).transposed().to_euler()
    scene.camera = camera
    return camera, toward_eye, up, right


def render(meshes, out, options):
    """Cycles, CPU, lit by a sun, from `tiledtex render`'s viewpoint."""
    scene = bpy.context.scene
    camera, toward_eye, up, right = add_camera_like_render(meshes, options, options['size'], options['size'])
    sun_data = bpy.data.lights.new('key', 'SUN')
    sun_data.energy = 3.0
    sun = bpy.data.objects.new('key', sun_data)
    # From above the camera, a little to its right.
    sun.rotation_euler = (-(toward_eye + up * 0.8 + right * 0.5)).to_track_quat('-Z', 'Y').to_euler()
    scene.collection.objects.link(sun)
    use_cycles_on_cpu(scene, options['samples'], 0.35)
    scene.render.resolution_x = scene.render.resolution_y = options['size']
    scene.render.resolution_percentage = 100
    # Plain sRGB, as the tool writes its pictures (Blender's default, Filmic, flattens them).
    scene.view_settings.view_transform = 'Standard'
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)
    print(f"blender: rendered {out}")


def restore_numpy_bool():
    """Debian 12's Blender 3.4 glTF importer still says numpy.bool, which
    numpy 1.24 removed (it was the builtin bool all along): give it back."""
    import warnings
    import numpy
    # Asking numpy 1.24 about the name warns that it may come back one day.
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', FutureWarning)
        missing = not hasattr(numpy, 'bool')
    if missing:
        numpy.bool = bool


def main():
    path, out, options = parse_arguments(sys.argv)
    restore_numpy_bool()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    result = bpy.ops.import_scene.gltf(filepath=path)
    if 'FINISHED' not in result:
        sys.exit(f"blender: could not import {path}")
    ok, meshes = describe(list(bpy.context.scene.objects))
    if ok and options['obj']:
        ok = compare_with_obj(meshes, options['obj'])
    if ok and out:
        render(meshes, out, options)
    sys.exit(0 if ok else 1)


# Blender runs a --python script as __main__; tests/import_check.py imports it.
if __name__ == '__main__':
    main()
