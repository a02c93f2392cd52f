#include "ob_input.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Where a drag starts: only the deltas matter to the listeners. */
#define DRAG_X0 100.0
#define DRAG_Y0 100.0

static bool fail(char *why, size_t size, const char *fmt, ...)
{
    if (why && size) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(why, size, fmt, ap);
        va_end(ap);
    }
    return false;
}

static bool word_is(const char *s, size_t n, const char *w) { return strlen(w) == n && !strncmp(s, w, n); }

static bool ieq(const char *s, size_t n, const char *w)
{
    if (strlen(w) != n) return false;
    for (size_t i = 0; i < n; i++)
        if (tolower((unsigned char)s[i]) != tolower((unsigned char)w[i])) return false;
    return true;
}

/* "shift+" in front of a key or a button. */
static bool take_shift(const char **s, size_t *n)
{
    if (*n > 6 && ieq(*s, 6, "shift+")) {
        *s += 6;
        *n -= 6;
        return true;
    }
    return false;
}

static int key_from_name(const char *s, size_t n)
{
    if (n == 1 && isalnum((unsigned char)s[0])) return toupper((unsigned char)s[0]);
    if (ieq(s, n, "escape") || ieq(s, n, "esc")) return OB_KEY_ESCAPE;
    if ((n == 2 || n == 3) && (s[0] == 'F' || s[0] == 'f')) {
        int k = 0;
        for (size_t i = 1; i < n; i++) {
            if (!isdigit((unsigned char)s[i])) return -1;
            k = k * 10 + (s[i] - '0');
        }
        if (k >= 1 && k <= 12) return OB_KEY_F1 + k - 1;
    }
    return -1;
}

const char *ob_input_key_name(int key, char buf[8])
{
    if (key == OB_KEY_ESCAPE) return "Escape";
    if (key >= OB_KEY_F1 && key < OB_KEY_F1 + 12) snprintf(buf, 8, "F%d", key - OB_KEY_F1 + 1);
    else if (key > ' ' && key < 127) snprintf(buf, 8, "%c", key);
    else snprintf(buf, 8, "#%d", key & 0xffff);
    return buf;
}

/* The next blank-separated token of [*p, end): start and length. */
static bool token(const char **p, const char *end, const char **tok, size_t *len)
{
    while (*p < end && isspace((unsigned char)**p)) (*p)++;
    *tok = *p;
    while (*p < end && !isspace((unsigned char)**p)) (*p)++;
    *len = (size_t)(*p - *tok);
    return *len > 0;
}

static bool number(const char *tok, size_t len, double *out)
{
    char buf[40];
    if (!len || len >= sizeof buf) return false;
    memcpy(buf, tok, len);
    buf[len] = '\0';
    char *end;
    errno = 0;
    double v = strtod(buf, &end);
    if (*end || errno == ERANGE || !isfinite(v)) return false;
    *out = v;
    return true;
}

static bool push(ob_input_script *s, ob_input_event e, char *why, size_t size)
{
    if (s->count == OB_INPUT_SCRIPT_MAX)
        return fail(why, size, "more than %d events (a drag counts four)", OB_INPUT_SCRIPT_MAX);
    s->events[s->count++] = e;
    return true;
}

/* One "FRAME:ACTION ARGS" in [p, end), blanks around it already allowed. */
static bool parse_event(ob_input_script *s, const char *p, const char *end, char *why, size_t size)
{
    const char *tok;
    size_t len;
    const char *start = p;
    while (p < end && isspace((unsigned char)*p)) p++;
    const char *colon = memchr(p, ':', (size_t)(end - p));
    int shown = (int)(end - start > 60 ? 60 : end - start);
    if (!colon || colon == p)
        return fail(why, size, "'%.*s': expected FRAME:ACTION (e.g. 3:key W)", shown, start);
    char *num_end;
    char frame_text[16] = "";
    if ((size_t)(colon - p) >= sizeof frame_text || !isdigit((unsigned char)*p))
        return fail(why, size, "'%.*s': the frame must be a number from 0", shown, start);
    memcpy(frame_text, p, (size_t)(colon - p));
    errno = 0;
    unsigned long frame = strtoul(frame_text, &num_end, 10);
    if (*num_end || errno == ERANGE || frame > UINT32_MAX)
        return fail(why, size, "'%.*s': the frame must be a number from 0", shown, start);
    p = colon + 1;
    ob_input_event e = {.frame = (uint32_t)frame};
    if (!token(&p, end, &tok, &len))
        return fail(why, size, "'%.*s': no action (key, drag or wheel)", shown, start);
    if (word_is(tok, len, "key")) {
        if (!token(&p, end, &tok, &len)) return fail(why, size, "'%.*s': key needs a name", shown, start);
        e.kind = OB_INPUT_KEY;
        e.shift = take_shift(&tok, &len);
        e.key = key_from_name(tok, len);
        if (e.key < 0)
            return fail(why, size, "'%.*s': unknown key '%.*s' (A-Z, 0-9, F1-F12, Escape)", shown, start,
                        (int)len, tok);
        if (!push(s, e, why, size)) return false;
    } else if (word_is(tok, len, "drag")) {
        if (!token(&p, end, &tok, &len)) return fail(why, size, "'%.*s': drag needs a button", shown, start);
        bool shift = take_shift(&tok, &len);
        ob_mouse_button b;
        if (ieq(tok, len, "left")) b = OB_BUTTON_LEFT;
        else if (ieq(tok, len, "right")) b = OB_BUTTON_RIGHT;
        else if (ieq(tok, len, "middle")) b = OB_BUTTON_MIDDLE;
        else
            return fail(why, size, "'%.*s': unknown button '%.*s' (left, middle, right)", shown, start,
                        (int)len, tok);
        double dx, dy;
        const char *t2;
        size_t l2;
        if (!token(&p, end, &tok, &len) || !number(tok, len, &dx) || !token(&p, end, &t2, &l2) ||
            !number(t2, l2, &dy))
            return fail(why, size, "'%.*s': drag needs two numbers, DX DY (pixels)", shown, start);
        ob_input_event ev[4] = {
            {.frame = e.frame, .kind = OB_INPUT_CURSOR, .x = DRAG_X0, .y = DRAG_Y0},
            {.frame = e.frame, .kind = OB_INPUT_BUTTON, .button = b, .down = true, .shift = shift},
            {.frame = e.frame, .kind = OB_INPUT_CURSOR, .x = DRAG_X0 + dx, .y = DRAG_Y0 + dy},
            {.frame = e.frame, .kind = OB_INPUT_BUTTON, .button = b, .down = false, .shift = shift},
        };
        for (int i = 0; i < 4; i++)
            if (!push(s, ev[i], why, size)) return false;
    } else if (word_is(tok, len, "wheel")) {
        e.kind = OB_INPUT_SCROLL;
        if (!token(&p, end, &tok, &len) || !number(tok, len, &e.x))
            return fail(why, size, "'%.*s': wheel needs a number of steps", shown, start);
        if (!push(s, e, why, size)) return false;
    } else {
        return fail(why, size, "'%.*s': unknown action '%.*s' (key, drag or wheel)", shown, start,
                    (int)len, tok);
    }
    if (token(&p, end, &tok, &len))
        return fail(why, size, "'%.*s': unexpected '%.*s' at the end", shown, start, (int)len, tok);
    return true;
}

bool ob_input_script_parse(const char *text, ob_input_script *s, char *why, size_t why_size)
{
    s->count = s->next = 0;
    if (why && why_size) why[0] = '\0';
    const char *p = text ? text : "";
    while (*p) {
        const char *end = p;
        while (*end && *end != ';' && *end != '\n' && *end != '#') end++;
        const char *q = p;
        while (q < end && isspace((unsigned char)*q)) q++;
        if (q < end && !parse_event(s, p, end, why, why_size)) {
            s->count = 0;
            return false;
        }
        if (*end == '#')
            while (*end && *end != '\n') end++;
        p = *end ? end + 1 : end;
    }
    /* Stable sort by frame (insertion: a few hundred events at most). */
    for (uint32_t i = 1; i < s->count; i++) {
        ob_input_event e = s->events[i];
        uint32_t j = i;
        while (j > 0 && s->events[j - 1].frame > e.frame) {
            s->events[j] = s->events[j - 1];
            j--;
        }
        s->events[j] = e;
    }
    return true;
}

void ob_input_deliver(const ob_input_event *e, const ob_input_handler *h)
{
    if (!h) return;
    switch (e->kind) {
    case OB_INPUT_KEY:
        if (h->key) h->key(h->user, e->key, e->shift);
        break;
    case OB_INPUT_BUTTON:
        if (h->button) h->button(h->user, e->button, e->down, e->shift);
        break;
    case OB_INPUT_CURSOR:
        if (h->cursor) h->cursor(h->user, e->x, e->y);
        break;
    case OB_INPUT_SCROLL:
        if (h->scroll) h->scroll(h->user, e->x);
        break;
    }
}

uint32_t ob_input_script_play(ob_input_script *s, uint32_t frame, const ob_input_handler *h)
{
    uint32_t n = 0;
    while (s->next < s->count && s->events[s->next].frame <= frame) {
        ob_input_deliver(&s->events[s->next++], h);
        n++;
    }
    return n;
}
