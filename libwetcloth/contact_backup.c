#include "contact_backup.h"

#include <string.h>

#include "alloc.h"

static size_t cloth_bytes(const wc_cloth *c)
{
    size_t n = (size_t)c->particle_count, pairs = (size_t)c->adhesive_count;
    return 3 * n * sizeof(double) + n + sizeof(int64_t) + pairs * (2 * sizeof(int32_t) + 6 * sizeof(double));
}

static unsigned char *put(unsigned char *at, const void *from, size_t bytes)
{
    if (bytes) memcpy(at, from, bytes);
    return at + bytes;
}

static const unsigned char *get(const unsigned char *at, void *to, size_t bytes)
{
    if (bytes) memcpy(to, at, bytes);
    return at + bytes;
}

int wci_contact_backup_save(wc_contact_backup *b, wc_cloth *const *cloths, int32_t count)
{
    size_t total = 0;
    for (int32_t k = 0; k < count; ++k) total += cloth_bytes(cloths[k]);
    if (total > b->capacity) {
        unsigned char *grown = wci_alloc_array(total, 1);
        if (!grown) return 1;
        wci_free(b->bytes);
        b->bytes = grown;
        b->capacity = total;
    }
    unsigned char *at = b->bytes;
    for (int32_t k = 0; k < count; ++k) {
        const wc_cloth *c = cloths[k];
        size_t n = (size_t)c->particle_count, pairs = (size_t)c->adhesive_count;
        at = put(at, c->normal_x, n * sizeof(double));
        at = put(at, c->normal_y, n * sizeof(double));
        at = put(at, c->normal_z, n * sizeof(double));
        at = put(at, c->contact, n);
        at = put(at, &c->adhesive_count, sizeof(int64_t));
        at = put(at, c->adhesive_pairs, pairs * 2 * sizeof(int32_t));
        at = put(at, c->adhesive_data, pairs * 6 * sizeof(double));
    }
    return 0;
}

void wci_contact_backup_restore(const wc_contact_backup *b, wc_cloth *const *cloths, int32_t count)
{
    const unsigned char *at = b->bytes;
    for (int32_t k = 0; k < count; ++k) {
        wc_cloth *c = cloths[k];
        size_t n = (size_t)c->particle_count;
        at = get(at, c->normal_x, n * sizeof(double));
        at = get(at, c->normal_y, n * sizeof(double));
        at = get(at, c->normal_z, n * sizeof(double));
        at = get(at, c->contact, n);
        int64_t pairs;
        at = get(at, &pairs, sizeof pairs);
        /* the pair buffers only grow, so the saved pairs still fit */
        at = get(at, c->adhesive_pairs, (size_t)pairs * 2 * sizeof(int32_t));
        at = get(at, c->adhesive_data, (size_t)pairs * 6 * sizeof(double));
        c->adhesive_count = pairs;
        c->self_touched_count = 0;
        c->self_touched_failed = 0;
    }
}

void wci_contact_backup_destroy(wc_contact_backup *b)
{
    wci_free(b->bytes);
    b->bytes = NULL;
    b->capacity = 0;
}
