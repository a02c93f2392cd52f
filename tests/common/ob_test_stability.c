#define _POSIX_C_SOURCE 200809L
#include "ob_test_stability.h"

#include <math.h>
#include <stdlib.h>

#include "ob_bench_stability.h"

void ob_test_stability_run(void **state)
{
    const char *label = *state;
    ob_test_setup_log();
    /* As ob_test_world: every renderer a case makes runs under validation. */
    setenv("OB_VALIDATION", "1", 1);
    ob_heap_stats before = ob_heap_stats_now();
    ob_bench_stability s;
    ob_result r = ob_bench_stability_run(&(ob_bench_stability_desc){.only = label}, &s);
    for (uint32_t i = 0; i < s.count; i++) {
        const ob_bench_stability_row *row = &s.rows[i];
        char bound[32] = "measured only";
        if (!isnan(row->bound)) snprintf(bound, sizeof bound, "bound %.7g", row->bound);
        print_message("%s: %.7g %s (%s) %s: %s; %s\n", row->name, row->error, row->unit, bound,
                      row->pass ? "ok" : "FAILED", row->measure, row->detail);
    }
    uint32_t rows = s.count, failed = s.failed, messages = s.validation_messages;
    bool rendered = s.device_name[0] != '\0', validation = s.validation;
    ob_bench_stability_release(&s);
    ob_heap_stats after = ob_heap_stats_now();
    if (r != OB_OK) fail_msg("case '%s' could not run: %s", label, ob_result_name(r));
    if (rows == 0) fail_msg("case '%s' gave no row", label);
    if (failed) fail_msg("case '%s': %u of %u rows failed", label, failed, rows);
    if (rendered && !validation) fail_msg("case '%s' rendered without the validation layer", label);
    if (messages) fail_msg("case '%s': the validation layer reported %u messages", label, messages);
    /* What a case made is gone: a leak the sanitizer build would also catch,
     * but this also catches memory kept in a list until exit. */
    if (after.live_blocks != before.live_blocks || after.live_bytes != before.live_bytes)
        fail_msg("case '%s': Obelisk's heap holds %lld blocks (%lld bytes) more after it",
                 label, (long long)(after.live_blocks - before.live_blocks),
                 (long long)(after.live_bytes - before.live_bytes));
}
