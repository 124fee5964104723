/* cross_positions: the same two scenes on every platform, their positions
 * written exactly, and compared with another platform's.
 *
 *   cross_positions OUT [REFERENCE]
 *
 * Runs two scenes that are not chaotic, so that a difference in the last
 * bit of one operation stays about that small instead of growing:
 *
 *   free_fall  an 8 x 8 cloth, 0.5 m wide, falling flat from rest for one
 *              second (gravity, springs at rest length, air drag);
 *   hanging    a 16 x 16 cotton cloth, 1 m wide, held by two corners,
 *              swinging and settling for two seconds (stretch and bend
 *              springs, buckling, pins, substeps from the stable step).
 *
 * and writes, at a few frames, every particle's x, y, z as %.17g and as the
 * 64 bits of the double in hexadecimal, one particle a line, to OUT. With
 * REFERENCE (the same file from another build: scripts/test-windows.sh
 * passes the Linux build's), it compares the bits read back from both and
 * fails when any coordinate differs by more than 1e-12 m, printing how many
 * values differ at all and the largest difference.
 *
 * Uses only the public header and the shared library, as any program would.
 * Exit status 0 on success, 1 on a failed call or comparison, 2 on usage.
 */
#include <wetcloth.h>

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TOLERANCE 1e-12
#define MAX_PARTICLES 256
#define MAX_LINES 4096

typedef struct {
    char scene[16];
    int frame, particle;
    uint64_t bits[3];
} record;

static int check(wc_status s, wc_world *world, const char *what)
{
    if (s == WC_OK) return 1;
    fprintf(stderr, "cross_positions: %s failed: %s\n", what, world ? wc_world_last_error(world) : "");
    return 0;
}

static uint64_t bits_of(double v)
{
    uint64_t b;
    memcpy(&b, &v, sizeof b);
    return b;
}

static double double_of(uint64_t b)
{
    double v;
    memcpy(&v, &b, sizeof v);
    return v;
}

/* Runs one scene and writes the frames listed in `frames` (ascending, 0-ended). */
static int run_scene(FILE *out, const char *scene, int n, double size, int pinned, int frame_count,
                     const int *frames)
{
    wc_world_def world_def = wc_world_def_default();
    wc_grid_cloth_def grid = wc_grid_cloth_def_default();
    wc_message message;
    wc_world *world = NULL;
    int32_t cloth, corners[2];
    double xyz[3 * MAX_PARTICLES];
    int next = 0, ok = 1;

    world_def.thread_count = 1;
    if (wc_world_create(&world_def, &world, &message) != WC_OK) {
        fprintf(stderr, "cross_positions: wc_world_create failed: %s\n", message.text);
        return 0;
    }
    grid.count_u = grid.count_v = n;
    grid.size_u = grid.size_v = size;
    grid.center[2] = 1.0;
    corners[0] = 0;
    corners[1] = n - 1;
    ok = check(wc_world_add_grid_cloth(world, &grid, &cloth), world, "wc_world_add_grid_cloth") &&
         (!pinned || check(wc_cloth_pin(world, cloth, corners, 2), world, "wc_cloth_pin"));
    for (int f = 1; ok && f <= frame_count; ++f) {
        ok = check(wc_world_advance(world, 1.0 / 24.0, 0), world, "wc_world_advance");
        if (!ok || f != frames[next]) continue;
        ++next;
        ok = check(wc_cloth_get_positions(world, cloth, xyz, n * n), world, "wc_cloth_get_positions");
        for (int i = 0; ok && i < n * n; ++i) {
            const double *p = xyz + 3 * i;
            if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) {
                fprintf(stderr, "cross_positions: %s frame %d particle %d is not finite\n", scene, f, i);
                ok = 0;
            }
            fprintf(out, "%s %d %d %.17g %.17g %.17g %016" PRIx64 " %016" PRIx64 " %016" PRIx64 "\n",
                    scene, f, i, p[0], p[1], p[2], bits_of(p[0]), bits_of(p[1]), bits_of(p[2]));
        }
    }
    wc_world_destroy(world);
    return ok;
}

/* Reads a file written by this program into recs; returns the count, or -1. */
static int read_records(const char *path, record *recs)
{
    FILE *f = fopen(path, "r");
    char line[512];
    int count = 0;
    if (!f) {
        fprintf(stderr, "cross_positions: cannot open %s (run the build that writes it first)\n", path);
        return -1;
    }
    while (fgets(line, sizeof line, f)) {
        record *r = recs + count;
        double ignored[3];
        if (count == MAX_LINES ||
            sscanf(line, "%15s %d %d %lf %lf %lf %" SCNx64 " %" SCNx64 " %" SCNx64, r->scene,
                   &r->frame, &r->particle, &ignored[0], &ignored[1], &ignored[2], &r->bits[0],
                   &r->bits[1], &r->bits[2]) != 9) {
            fprintf(stderr, "cross_positions: %s line %d is not a position line\n", path, count + 1);
            fclose(f);
            return -1;
        }
        ++count;
    }
    fclose(f);
    return count;
}

static int compare(const char *path, const char *reference)
{
    record *a = malloc(MAX_LINES * sizeof *a), *b = malloc(MAX_LINES * sizeof *b);
    int na, nb, differ = 0, worst = -1, ok = 1;
    double max_diff = 0.0;
    if (!a || !b) {
        fprintf(stderr, "cross_positions: out of memory\n");
        free(a), free(b);
        return 0;
    }
    na = read_records(path, a);
    nb = read_records(reference, b);
    if (na < 0 || nb < 0) ok = 0;
    else if (na != nb) {
        fprintf(stderr, "cross_positions: %s has %d lines, %s %d\n", path, na, reference, nb);
        ok = 0;
    }
    for (int k = 0; ok && k < na; ++k) {
        if (strcmp(a[k].scene, b[k].scene) != 0 || a[k].frame != b[k].frame ||
            a[k].particle != b[k].particle) {
            fprintf(stderr, "cross_positions: line %d is %s frame %d particle %d in one file, "
                    "%s frame %d particle %d in the other\n", k + 1, a[k].scene, a[k].frame,
                    a[k].particle, b[k].scene, b[k].frame, b[k].particle);
            ok = 0;
            break;
        }
        for (int c = 0; c < 3; ++c) {
            double d = fabs(double_of(a[k].bits[c]) - double_of(b[k].bits[c]));
            if (a[k].bits[c] != b[k].bits[c]) ++differ;
            if (!(d <= max_diff)) max_diff = d, worst = k;
        }
    }
    if (ok) {
        printf("cross_positions: %d coordinates compared with %s: %d differ in their bits, "
               "largest difference %.3g m", 3 * na, reference, differ, max_diff);
        if (worst >= 0 && max_diff > 0.0)
            printf(" (%s, frame %d, particle %d)", a[worst].scene, a[worst].frame, a[worst].particle);
        printf("; bound %.0e m\n", TOLERANCE);
        if (!(max_diff <= TOLERANCE)) {
            fprintf(stderr, "cross_positions: the positions differ by more than %.0e m\n", TOLERANCE);
            ok = 0;
        }
    }
    free(a), free(b);
    return ok;
}

int main(int argc, char **argv)
{
    static const int free_fall_frames[] = {1, 12, 24, 0};
    static const int hanging_frames[] = {12, 24, 48, 0};
    FILE *out;
    int ok;

    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: cross_positions OUT [REFERENCE]\n");
        return 2;
    }
    out = fopen(argv[1], "w");
    if (!out) {
        fprintf(stderr, "cross_positions: cannot create %s\n", argv[1]);
        return 1;
    }
    ok = run_scene(out, "free_fall", 8, 0.5, 0, 24, free_fall_frames) &&
         run_scene(out, "hanging", 16, 1.0, 1, 48, hanging_frames);
    if (fclose(out) != 0) ok = 0;
    if (!ok) return 1;
    printf("cross_positions: wrote %s (libwetcloth %s)\n", argv[1], wc_version_string());
    if (argc == 3 && !compare(argv[1], argv[2])) return 1;
    return 0;
}
