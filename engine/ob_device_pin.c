/* ob_device_pin.c — keeping the Vulkan drivers loaded once a device exists.
 *
 * The loader opens the ICDs (and the layers) when an instance is created and
 * closes them when the last instance is destroyed, so a program that creates
 * and destroys renderers in turn loads and unloads the driver each time. The
 * NVIDIA driver's libnvidia-tls uses initial-exec TLS, which glibc takes
 * from a small static TLS reserve that a dlclose does not give back: on an
 * H100 (driver 580.159) a test process's instances failed after about a
 * dozen with "cannot allocate memory in static TLS block", then "Found no
 * drivers". A test binary, the benchmark and an editor that reopens scenes
 * all do this.
 *
 * So, right after each instance is created, every shared object then
 * loaded (the loader, the ICD, its dependencies, the layers) is re-opened
 * with RTLD_NOLOAD | RTLD_NODELETE: it stays mapped for the process's life
 * and later instances reuse it, as a program holding one instance
 * throughout would. Objects that were already loaded only gain a flag they
 * effectively had; doing it for every instance (tens of microseconds) also
 * pins a driver that a later instance is the first to load. Without glibc's
 * dl_iterate_phdr, nothing is done.
 */
#define _GNU_SOURCE
#include "ob_device_internal.h"

#if defined(__linux__) && defined(__GLIBC__)
#include <dlfcn.h>
#include <link.h>

static int pin_one(struct dl_phdr_info *info, size_t size, void *data)
{
    (void)size;
    (void)data;
    const char *name = info->dlpi_name;
    if (!name || !name[0]) return 0;  /* the program itself */
    /* The handle is kept on purpose: NODELETE already keeps the object. */
    (void)dlopen(name, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
    return 0;
}

void ob_device_pin_drivers(void)
{
    dl_iterate_phdr(pin_one, NULL);
}
#else
void ob_device_pin_drivers(void) {}
#endif
