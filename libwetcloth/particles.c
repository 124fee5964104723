#include "particles.h"

#include <stdint.h>
#include <string.h>

#include "alloc.h"

enum { DOUBLES = 22, INTS = 1, BYTES = 4 };

/* The per-particle arrays, the same order in a cloth and in the world. */
typedef struct fields {
    double **d[DOUBLES];
    int32_t **i[INTS];
    uint8_t **b[BYTES];
} fields;

static fields cloth_fields(wc_cloth *c)
{
    fields f = {{&c->x, &c->y, &c->z, &c->px, &c->py, &c->pz, &c->nx, &c->ny, &c->nz, &c->fx,
                 &c->fy, &c->fz, &c->mass, &c->inv_mass, &c->normal_x, &c->normal_y,
                 &c->normal_z, &c->qx, &c->qy, &c->qz, &c->wetness, &c->grip},
                {&c->pin_slot},
                {&c->contact, &c->contact_prev, &c->stuck, &c->history_override}};
    return f;
}

static fields world_fields(wc_particles *p)
{
    fields f = {{&p->x, &p->y, &p->z, &p->px, &p->py, &p->pz, &p->nx, &p->ny, &p->nz, &p->fx,
                 &p->fy, &p->fz, &p->mass, &p->inv_mass, &p->normal_x, &p->normal_y,
                 &p->normal_z, &p->qx, &p->qy, &p->qz, &p->wetness, &p->grip},
                {&p->pin_slot},
                {&p->contact, &p->contact_prev, &p->stuck, &p->history_override}};
    return f;
}

/* A cloth's views at its range of the world's arrays. */
static void point(wc_particles *p, wc_cloth *c)
{
    fields cf = cloth_fields(c), wf = world_fields(p);
    size_t at = (size_t)c->first;
    for (int k = 0; k < DOUBLES; ++k) *cf.d[k] = *wf.d[k] + at;
    for (int k = 0; k < INTS; ++k) *cf.i[k] = *wf.i[k] + at;
    for (int k = 0; k < BYTES; ++k) *cf.b[k] = *wf.b[k] + at;
}

/* A cloth's state, through its current pointers, into its new range. */
static void copy_into(wc_particles *p, wc_cloth *c, size_t at)
{
    fields cf = cloth_fields(c), wf = world_fields(p);
    size_t n = (size_t)c->particle_count;
    for (int k = 0; k < DOUBLES; ++k) memcpy(*wf.d[k] + at, *cf.d[k], n * sizeof(double));
    for (int k = 0; k < INTS; ++k) memcpy(*wf.i[k] + at, *cf.i[k], n * sizeof(int32_t));
    for (int k = 0; k < BYTES; ++k) memcpy(*wf.b[k] + at, *cf.b[k], n);
}

int wci_particles_add(wc_particles *p, wc_cloth *const *cloths, int32_t count)
{
    int64_t total = 0;
    for (int32_t c = 0; c < count; ++c) total += cloths[c]->particle_count;
    const size_t per = DOUBLES * sizeof(double) + INTS * sizeof(int32_t) + BYTES;
    if (total > INT32_MAX || (uint64_t)total > SIZE_MAX / per) return 1;
    size_t n = (size_t)total;
    /* doubles first, then the int32 and byte arrays: each array aligned */
    unsigned char *block = wci_alloc_array(n, per);
    if (!block) return 1;
    wc_particles q;
    memset(&q, 0, sizeof q);
    q.count = (int32_t)total;
    q.block = block;
    fields wf = world_fields(&q);
    double *doubles = (double *)(void *)block;
    int32_t *ints = (int32_t *)(void *)(doubles + DOUBLES * n);
    uint8_t *bytes = (uint8_t *)(ints + INTS * n);
    for (int k = 0; k < DOUBLES; ++k) *wf.d[k] = doubles + k * n;
    for (int k = 0; k < INTS; ++k) *wf.i[k] = ints + k * n;
    for (int k = 0; k < BYTES; ++k) *wf.b[k] = bytes + k * n;
    /* the cloths that collide with cloths first, then the others, each in
     * world order: the group's members are one range (cloth_group.c) */
    size_t at = 0;
    for (int pass = 0; pass < 2; ++pass)
        for (int32_t c = 0; c < count; ++c) {
            wc_cloth *cl = cloths[c];
            if ((cl->collide_cloths != 0) != (pass == 0)) continue;
            copy_into(&q, cl, at);
            cl->first = (int32_t)at;
            at += (size_t)cl->particle_count;
        }
    for (int32_t c = 0; c < count; ++c) {
        wc_cloth *cl = cloths[c];
        if (!cl->in_world) wci_particles_free_own(cl);
        cl->in_world = 1;
        point(&q, cl);
    }
    wci_free(p->block);
    *p = q;
    return 0;
}

void wci_particles_commit(wc_particles *p, wc_cloth *const *cloths, int32_t count)
{
    double *t;
    t = p->px, p->px = p->x, p->x = p->nx, p->nx = t;
    t = p->py, p->py = p->y, p->y = p->ny, p->ny = t;
    t = p->pz, p->pz = p->z, p->z = p->nz, p->nz = t;
    for (int32_t c = 0; c < count; ++c) point(p, cloths[c]);
}

void wci_particles_view(wc_cloth *view, const wc_cloth *from)
{
    fields vf = cloth_fields(view), ff = cloth_fields((wc_cloth *)from);
    for (int k = 0; k < DOUBLES; ++k) *vf.d[k] = *ff.d[k];
    for (int k = 0; k < INTS; ++k) *vf.i[k] = *ff.i[k];
    for (int k = 0; k < BYTES; ++k) *vf.b[k] = *ff.b[k];
}

void wci_particles_free_own(wc_cloth *c)
{
    fields f = cloth_fields(c);
    for (int k = 0; k < DOUBLES; ++k) wci_free(*f.d[k]), *f.d[k] = NULL;
    for (int k = 0; k < INTS; ++k) wci_free(*f.i[k]), *f.i[k] = NULL;
    for (int k = 0; k < BYTES; ++k) wci_free(*f.b[k]), *f.b[k] = NULL;
}

void wci_particles_free(wc_particles *p)
{
    wci_free(p->block);
    memset(p, 0, sizeof *p);
}
