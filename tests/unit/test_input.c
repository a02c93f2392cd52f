/* Scripted input (demos/app/ob_input.h, obelisk-view --input): a script
 * replays what a user does in the window, so a test that drives the viewer
 * headless checks the same handlers. What breaks for a user: events at the
 * wrong frame or in the wrong order, a drag that does not move, a typo in a
 * script taken silently. */
#include <stdio.h>
#include <string.h>

#include "ob_input.h"
#include "ob_test.h"

typedef struct recorder {
    char log[1024];
} recorder;

static void rec(recorder *r, const char *line)
{
    size_t n = strlen(r->log);
    snprintf(r->log + n, sizeof r->log - n, "%s%s", n ? "|" : "", line);
}

static void on_key(void *user, int key, bool shift)
{
    char name[8], line[32];
    snprintf(line, sizeof line, "key %s%s", shift ? "shift+" : "", ob_input_key_name(key, name));
    rec(user, line);
}

static void on_button(void *user, ob_mouse_button b, bool down, bool shift)
{
    char line[32];
    snprintf(line, sizeof line, "%s %d%s", down ? "down" : "up", (int)b, shift ? " shift" : "");
    rec(user, line);
}

static void on_cursor(void *user, double x, double y)
{
    char line[48];
    snprintf(line, sizeof line, "at %g,%g", x, y);
    rec(user, line);
}

static void on_scroll(void *user, double steps)
{
    char line[32];
    snprintf(line, sizeof line, "wheel %g", steps);
    rec(user, line);
}

static void script_plays_in_frame_order(void **state)
{
    (void)state;
    static ob_input_script s;
    char why[160];
    assert_true(ob_input_script_parse("5:key w; 2:wheel -1.5\n"
                                      "# a comment line\n"
                                      "2:drag shift+left 30 -10   # pan\n"
                                      "0:key F1;7:key escape",
                                      &s, why, sizeof why));
    assert_int_equal(s.count, 1 + 1 + 4 + 1 + 1);
    recorder r = {""};
    ob_input_handler h = {on_key, on_button, on_cursor, on_scroll, &r};
    assert_int_equal(ob_input_script_play(&s, 0, &h), 1);
    assert_string_equal(r.log, "key F1");
    r.log[0] = '\0';
    assert_int_equal(ob_input_script_play(&s, 1, &h), 0);
    /* Frame 2: the wheel and the drag, in the order written. */
    assert_int_equal(ob_input_script_play(&s, 2, &h), 5);
    assert_string_equal(r.log, "wheel -1.5|at 100,100|down 0 shift|at 130,90|up 0 shift");
    r.log[0] = '\0';
    /* A frame skipped (a late start) still gets what was due. */
    assert_int_equal(ob_input_script_play(&s, 9, &h), 2);
    assert_string_equal(r.log, "key W|key Escape");
    assert_int_equal(ob_input_script_play(&s, 10, &h), 0);
}

/* A bad script is refused with a message naming the event; nothing of it
 * is kept. */
static void bad_scripts_are_refused_with_the_event(void **state)
{
    (void)state;
    static ob_input_script s;
    static const struct { const char *text, *needle; } cases[] = {
        {"key W", "expected FRAME:ACTION"},
        {"x:key W", "the frame must be a number"},
        {"-1:key W", "the frame must be a number"},
        {"3:press left", "unknown action 'press'"},
        {"3:key WW", "unknown key 'WW'"},
        {"3:key F13", "unknown key 'F13'"},
        {"3:drag top 1 2", "unknown button 'top'"},
        {"3:drag left 1", "drag needs two numbers"},
        {"3:wheel lots", "wheel needs a number"},
        {"3:wheel 1 2", "unexpected '2'"},
        {"1:key A; 2:key", "key needs a name"},
    };
    for (size_t i = 0; i < OB_ARRAY_COUNT(cases); i++) {
        char why[160] = "";
        assert_false(ob_input_script_parse(cases[i].text, &s, why, sizeof why));
        if (!strstr(why, cases[i].needle)) fail_msg("'%s': '%s' lacks '%s'", cases[i].text, why, cases[i].needle);
        assert_int_equal(s.count, 0);
    }
    /* Too many events. */
    char big[8192] = "";
    for (int i = 0; i < 70; i++) strcat(big, "1:drag left 1 1;");
    char why[160];
    assert_false(ob_input_script_parse(big, &s, why, sizeof why));
    assert_non_null(strstr(why, "more than"));
    /* Empty and blank scripts are fine. */
    assert_true(ob_input_script_parse("", &s, why, sizeof why));
    assert_true(ob_input_script_parse(" ; \n# nothing\n", &s, why, sizeof why));
    assert_int_equal(s.count, 0);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(script_plays_in_frame_order),
        cmocka_unit_test(bad_scripts_are_refused_with_the_event),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
