/* What a step changes before it knows it will succeed, besides the new
 * positions (which go to nx/ny/nz and are committed only at the end): each
 * particle's contact and its normal, and the self-adhesion pairs, which the
 * next step's wet forces read. A step saves them before collision and puts
 * them back when collision fails (out of memory, or a non-finite response),
 * so a failed step leaves the world as it was and a retry gives the same
 * bits as a run that never failed. */
#ifndef WC_CONTACT_BACKUP_H
#define WC_CONTACT_BACKUP_H

#include <stddef.h>
#include <stdint.h>

#include "cloth.h"

typedef struct wc_contact_backup {
    unsigned char *bytes;
    size_t capacity;
} wc_contact_backup;

/// Saves the cloths' contact state; non-zero when out of memory (then
/// nothing was changed).
int wci_contact_backup_save(wc_contact_backup *backup, wc_cloth *const *cloths, int32_t count);

/// Puts back what the last save saved, and drops the self-contacts a failed
/// step had recorded.
void wci_contact_backup_restore(const wc_contact_backup *backup, wc_cloth *const *cloths,
                               int32_t count);

void wci_contact_backup_destroy(wc_contact_backup *backup);

#endif
