#define _POSIX_C_SOURCE 200809L
#include "ob_test_stability.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "ob_stability.h"

/* What the test concludes of one row, from its numbers alone (never from
 * the case's verdict); why: the failure message when it fails. */
static ob_stability_verdict judge(const char *label, const ob_stability_row *row, char *why,
                                  size_t why_size)
{
    if (!row->checks_ok) {
        snprintf(why, why_size, "case '%s', row '%s': a check of the case failed: %s", label,
                 row->name, row->detail);
        return OB_STABILITY_FAIL;
    }
    if (isnan(row->error)) {
        snprintf(why, why_size, "case '%s', row '%s': nothing was measured (%s)", label, row->name,
                 row->measure);
        return OB_STABILITY_FAIL;
    }
    if (isnan(row->bound)) return OB_STABILITY_MEASURED;
    if (!(row->error <= row->bound)) {
        snprintf(why, why_size, "case '%s', row '%s': %s measured %.7g %s, over the bound %.7g %s (%s)",
                 label, row->name, row->measure, row->error, row->unit, row->bound, row->unit,
                 row->detail);
        return OB_STABILITY_FAIL;
    }
    return OB_STABILITY_PASS;
}

void ob_test_stability_run(void **state)
{
    const char *label = *state;
    ob_test_setup_log();
    /* As ob_test_world: every renderer a case makes runs under validation. */
    setenv("OB_VALIDATION", "1", 1);
    ob_heap_stats before = ob_heap_stats_now();
    ob_stability s;
    ob_result r = ob_stability_run(&(ob_stability_desc){.only = label}, &s);
    uint32_t bounded = 0, measured = 0, failed = 0;
    char why[1024] = "";
    for (uint32_t i = 0; i < s.count; i++) {
        const ob_stability_row *row = &s.rows[i];
        char row_why[1024];
        ob_stability_verdict v = judge(label, row, row_why, sizeof row_why);
        char bound[32] = "measured only";
        if (!isnan(row->bound)) snprintf(bound, sizeof bound, "bound %.7g", row->bound);
        print_message("%s: %.7g %s (%s) %s: %s; %s\n", row->name, row->error, row->unit, bound,
                      v == OB_STABILITY_FAIL ? "FAILED" : v == OB_STABILITY_PASS ? "ok" : "-",
                      row->measure, row->detail);
        bounded += !isnan(row->bound);
        measured += v == OB_STABILITY_MEASURED;
        if (v == OB_STABILITY_FAIL && !failed++) snprintf(why, sizeof why, "%s", row_why);
        /* What obelisk-bench reports for the row is what the test asserts. */
        if (v != OB_STABILITY_FAIL && row->verdict != v && !failed++)
            snprintf(why, sizeof why, "case '%s', row '%s': the case's verdict is '%s', the test's '%s'",
                     label, row->name, ob_stability_verdict_name(row->verdict),
                     ob_stability_verdict_name(v));
    }
    uint32_t rows = s.count, messages = s.validation_messages;
    bool rendered = s.device_name[0] != '\0', validation = s.validation;
    ob_stability_release(&s);
    ob_heap_stats after = ob_heap_stats_now();
    if (r != OB_OK) fail_msg("case '%s' could not run: %s", label, ob_result_name(r));
    if (rows == 0) fail_msg("case '%s' gave no row", label);
    if (failed) fail_msg("%s (%u of %u rows failed)", why, failed, rows);
    if (bounded == 0) fail_msg("case '%s': none of its %u rows has a bound to assert", label, rows);
    print_message("case '%s': %u rows within their bounds, %u measured only\n", label,
                  rows - measured, measured);
    if (rendered && !validation) fail_msg("case '%s' rendered without the validation layer", label);
    if (messages) fail_msg("case '%s': the validation layer reported %u messages", label, messages);
    /* What a case made is gone: a leak the sanitizer build would also catch,
     * but this also catches memory kept in a list until exit. */
    if (after.live_blocks != before.live_blocks || after.live_bytes != before.live_bytes)
        fail_msg("case '%s': Obelisk's heap holds %lld blocks (%lld bytes) more after it",
                 label, (long long)(after.live_blocks - before.live_blocks),
                 (long long)(after.live_bytes - before.live_bytes));
}
