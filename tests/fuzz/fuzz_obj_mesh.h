/* fuzz_obj_mesh.h - the checks the fuzz targets of the tool's mesh readers
   (fuzz_obj, fuzz_mesh_file) share on an obj_mesh they read, or failed to: include after
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

/* A failed read leaves the mesh zeroed: no counts, no arrays. */
static inline void fz_check_obj_zeroed(const obj_mesh *m)
{
    CHECK(m->nverts == 0 && m->nfaces == 0 && m->ncorners == 0 && m->nuvs == 0 && m->nnormals == 0 &&
              m->ngroups == 0 && m->nmaterials == 0,
          "failed read left counts %d %d %d %d %d %d %d", m->nverts, m->nfaces, m->ncorners, m->nuvs, m->nnormals,
          m->ngroups, m->nmaterials);
    CHECK(!m->pos && !m->face_size && !m->corner_vert && !m->uv && !m->corner_uv && !m->normal &&
              !m->corner_normal && !m->face_group && !m->group_names && !m->face_material && !m->material_names &&
              !m->mtllib && !m->vert_line && !m->face_line,
          "failed read left pointers behind");
}

#endif /* TILEDTEX_FUZZ_OBJ_MESH_H */
