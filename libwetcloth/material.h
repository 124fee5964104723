#ifndef WC_MATERIAL_H
#define WC_MATERIAL_H

#include "wetcloth.h"

/// Checks every field against its documented range; names the first bad one.
wc_status wci_material_validate(const wc_material *material, wc_message *msg);

#endif
