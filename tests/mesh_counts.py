# tests/mesh_counts.py - how many triangles an OBJ or a GLB holds, counted
# from the file itself, so that an importer's count can be checked against
# what the tool wrote (tests/import_check.sh and tests/import_check.py).
#
#   python3 tests/mesh_counts.py FILE.obj|FILE.glb     prints the count
#
# An OBJ face of n corners is n - 2 triangles, as every importer fans it. A
# GLB's primitives are triangle lists (the only mode the tool writes): a
# third of their index count, or of their vertex count without indices.
import json
import struct
import sys

GLTF_TRIANGLES = 4


def obj_triangles(path):
    count = 0
    with open(path) as f:
        for line in f:
            words = line.split()
            if words and words[0] == 'f':
                count += len(words) - 3
    return count


def glb_triangles(path):
    with open(path, 'rb') as f:
        data = f.read()
    magic, version, _ = struct.unpack_from('<4sII', data, 0)
    json_length, json_type = struct.unpack_from('<I4s', data, 12)
    if magic != b'glTF' or version != 2 or json_type != b'JSON':
        raise ValueError(f"{path} is not a binary glTF 2.0 file")
    gltf = json.loads(data[20:20 + json_length])
    count = 0
    for mesh in gltf.get('meshes', []):
        for primitive in mesh['primitives']:
            if primitive.get('mode', GLTF_TRIANGLES) != GLTF_TRIANGLES:
                raise ValueError(f"{path}: a primitive of mode {primitive['mode']}, not triangles")
            accessor = primitive['indices'] if 'indices' in primitive else primitive['attributes']['POSITION']
            count += gltf['accessors'][accessor]['count'] // 3
    return count


def triangles(path):
    return glb_triangles(path) if path.lower().endswith('.glb') else obj_triangles(path)


if __name__ == '__main__':
    if len(sys.argv) != 2:
        sys.exit('usage: python3 tests/mesh_counts.py FILE.obj|FILE.glb')
    print(triangles(sys.argv[1]))
