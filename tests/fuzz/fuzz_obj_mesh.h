/* fuzz_obj_mesh.h - the checks the fuzz targets of the tool's mesh readers
   (fuzz_obj, fuzz_mesh_file) share on an obj_mesh they read: include after
   fuzz_common.h and tool.h. */
#ifndef TILEDTEX_FUZZ_OBJ_MESH_H
#define TILEDTEX_FUZZ_OBJ_MESH_H

/* The faces: sizes of at least 3 adding up to ncorners, group and material
   indices in range; every corner's vertex in range. */
static inline void fz_check_obj_faces(const obj_mesh *m)
{
    int i, c = 0;
    for (i = 0; i < m->nfaces; ++i) {
        CHECK(m->face_size[i] >= 3, "face %d has %d corners", i, m->face_size[i]);
        CHECK(m->face_size[i] <= m->ncorners - c, "face sizes overrun %d corners", m->ncorners);
        c += m->face_size[i];
        CHECK(m->face_group[i] >= 0 && m->face_group[i] < m->ngroups, "face %d group %d of %d", i, m->face_group[i],
              m->ngroups);
        CHECK(m->face_material[i] >= 0 && m->face_material[i] < m->nmaterials, "face %d material %d of %d", i,
              m->face_material[i], m->nmaterials);
    }
    CHECK(c == m->ncorners, "face sizes add up to %d, ncorners %d", c, m->ncorners);
    for (i = 0; i < m->ncorners; ++i)
        CHECK(m->corner_vert[i] >= 0 && m->corner_vert[i] < m->nverts, "corner %d vertex %d of %d", i,
              m->corner_vert[i], m->nverts);
}

#endif /* TILEDTEX_FUZZ_OBJ_MESH_H */
