#include "material.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "status.h"

wc_material wc_material_default(void)
{
    wc_material m;
    m.density = 0.15;
    m.stretch_stiffness = 1000.0;
    m.bend_stiffness = 1e-5;
    m.stretch_damping = 0.05;
    m.air_drag = 0.02;
    m.thickness = 0.005;
    m.friction = 0.5;
    m.adhesion = 30.0;
    m.spread = 0.5;
    m.wet_friction = 0.05;
    m.wet_grip = 60.0;
    m.wet_mass_gain = 1.0;
    m.wet_softening = 0.3;
    m.wicking = 0.0;
    m.drying = 0.0;
    return m;
}

static wc_status check_range(wc_message *msg, const char *field, double value, double lo,
                             double hi, int lo_open)
{
    int ok = isfinite(value) && (lo_open ? value > lo : value >= lo) && value <= hi;
    if (ok) return WC_OK;
    /* A value just past a bound (0.99 kept as a 32-bit float is 0.99000001)
     * would print as the bound itself with %g; then print all its digits. */
    double bound = value > hi ? hi : lo;
    char a[32], b[32];
    snprintf(a, sizeof a, "%g", value);
    snprintf(b, sizeof b, "%g", bound);
    int digits = strcmp(a, b) == 0 ? 17 : 6;
    return wci_fail(msg, WC_ERROR_INVALID_ARGUMENT,
                   "material.%s must be in %s%g, %g] but is %.*g", field, lo_open ? "(" : "[",
                   lo, hi, digits, value);
}

wc_status wci_material_validate(const wc_material *m, wc_message *msg)
{
    wc_status s;
    if ((s = check_range(msg, "density", m->density, 0.0, 1e3, 1))) return s;
    if ((s = check_range(msg, "stretch_stiffness", m->stretch_stiffness, 0.0, 1e9, 0))) return s;
    if ((s = check_range(msg, "bend_stiffness", m->bend_stiffness, 0.0, 1e3, 0))) return s;
    if ((s = check_range(msg, "stretch_damping", m->stretch_damping, 0.0, 1.0, 0))) return s;
    if ((s = check_range(msg, "air_drag", m->air_drag, 0.0, 1e4, 0))) return s;
    if ((s = check_range(msg, "thickness", m->thickness, 0.0, 1.0, 0))) return s;
    if ((s = check_range(msg, "friction", m->friction, 0.0, 10.0, 0))) return s;
    if ((s = check_range(msg, "adhesion", m->adhesion, 0.0, 1e6, 0))) return s;
    if ((s = check_range(msg, "spread", m->spread, 0.0, 1.0, 0))) return s;
    if ((s = check_range(msg, "wet_friction", m->wet_friction, 0.0, 1.0, 0))) return s;
    if ((s = check_range(msg, "wet_grip", m->wet_grip, 0.0, 1e6, 0))) return s;
    if ((s = check_range(msg, "wet_mass_gain", m->wet_mass_gain, 0.0, 10.0, 0))) return s;
    if ((s = check_range(msg, "wet_softening", m->wet_softening, 0.0, 0.99, 0))) return s;
    if ((s = check_range(msg, "wicking", m->wicking, 0.0, 1.0, 0))) return s;
    if ((s = check_range(msg, "drying", m->drying, 0.0, 100.0, 0))) return s;
    return WC_OK;
}
