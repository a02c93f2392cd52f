/* ob_input.h — the demos' input events and scripted input.
 *
 * One handler (ob_input_handler) receives every key, mouse button, cursor
 * and wheel event, whether GLFW produced it (ob_window_set_input) or a
 * script did (--input): the demo programs have one code path for both, so
 * what a user does in the window can be replayed headless in a test.
 *
 * A script is a list of events, each "FRAME:ACTION", separated by ';' or
 * newlines ('#' starts a comment to the end of the line). FRAME is the
 * 0-based frame before whose update the event is delivered, in the order
 * written. ACTIONs:
 *   key NAME               a key press: A-Z, 0-9, F1-F12, Escape; shift+NAME
 *   drag BUTTON DX DY      press BUTTON (left, middle, right; shift+left),
 *                          move the cursor by DX, DY pixels, release
 *   wheel STEPS            the wheel (positive: away from the user, zoom in)
 *
 * Lifecycle: ob_input_script_parse fills a plain struct; nothing to free.
 * Thread rule: none (no shared state). Failure: parse returns false with a
 * message naming the event and what was expected; the script is then empty.
 */
#ifndef OB_INPUT_H
#define OB_INPUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Keys: letters and digits are their upper-case ASCII codes ('W', '1'). */
enum {
    OB_KEY_ESCAPE = 256,
    OB_KEY_F1 = 257,          /* F1..F12 = OB_KEY_F1 + 0..11 */
};
typedef enum ob_mouse_button { OB_BUTTON_LEFT = 0, OB_BUTTON_RIGHT = 1, OB_BUTTON_MIDDLE = 2 } ob_mouse_button;

/* Callbacks of one listener; any may be NULL. Positions are in pixels
 * from the top-left corner, as GLFW gives them. */
typedef struct ob_input_handler {
    void (*key)(void *user, int key, bool shift);
    void (*button)(void *user, ob_mouse_button button, bool down, bool shift);
    void (*cursor)(void *user, double x, double y);
    void (*scroll)(void *user, double steps);
    void *user;
} ob_input_handler;

typedef enum ob_input_kind { OB_INPUT_KEY, OB_INPUT_BUTTON, OB_INPUT_CURSOR, OB_INPUT_SCROLL } ob_input_kind;

typedef struct ob_input_event {
    uint32_t frame;
    ob_input_kind kind;
    int key;                  /* OB_INPUT_KEY */
    ob_mouse_button button;   /* OB_INPUT_BUTTON */
    bool down, shift;
    double x, y;              /* OB_INPUT_CURSOR: position; OB_INPUT_SCROLL: x = steps */
} ob_input_event;

#define OB_INPUT_SCRIPT_MAX 256   /* events after expansion (a drag is four) */

typedef struct ob_input_script {
    ob_input_event events[OB_INPUT_SCRIPT_MAX];
    uint32_t count;
    uint32_t next;            /* the first event not yet played */
} ob_input_script;

/* Parses text into *s (events sorted by frame, stable). False with a
 * message in why (why_size bytes) for a malformed event or more than
 * OB_INPUT_SCRIPT_MAX events; *s is then empty. */
bool ob_input_script_parse(const char *text, ob_input_script *s, char *why, size_t why_size);
/* Delivers every event of frames up to `frame` not delivered yet to h, in
 * order; returns how many. */
uint32_t ob_input_script_play(ob_input_script *s, uint32_t frame, const ob_input_handler *h);
/* Sends one event to h (what play does per event, and the window per
 * GLFW callback). */
void ob_input_deliver(const ob_input_event *e, const ob_input_handler *h);

/* A key's name for messages ("W", "F1", "Escape"); buf needs 8 bytes. */
const char *ob_input_key_name(int key, char buf[8]);

#endif /* OB_INPUT_H */
