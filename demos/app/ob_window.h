/* ob_window.h — a GLFW window for the demos' --window: the window, its
 * events and its Vulkan surface. GLFW stays out of the library: the window
 * hands its surface to the renderer (ob_renderer_attach_surface), which owns
 * the swapchain and presents every frame from ob_renderer_end_frame.
 *
 * Built when GLFW is found (libglfw3-dev; -DOB_WITH_WINDOW=OFF leaves it out;
 * headless builds keep these functions, which then say so). The window is
 * opened before the renderer (the instance needs its surface extensions) and
 * attached after it. F1 asks the demo to toggle single/multi-threaded
 * recording; closing the window or Escape ends the loop. Other keys, mouse
 * buttons, the cursor and the wheel go to the listener set with
 * ob_window_set_input (ob_input.h), the one scripted input (--input) also
 * feeds; with a listener, F1 goes to it too. Resizing is followed: the
 * renderer hears of the new size and rebuilds its swapchain.
 *
 * Thread rule: render thread only (GLFW's main-thread rule).
 */
#ifndef OB_WINDOW_H
#define OB_WINDOW_H

#include "ob_input.h"
#include "ob_renderer.h"

typedef struct ob_window ob_window;

/* Opens a resizable window; NULL with a message when there is no display or
 * GLFW cannot start. *out_exts / *out_ext_count: the instance extensions
 * the device must enable (owned by GLFW). */
ob_window *ob_window_open(uint32_t width, uint32_t height, const char *title,
                          const char *const **out_exts, uint32_t *out_ext_count);
/* Creates the window's surface on the renderer's instance and attaches it
 * to the renderer. Failure: an error result, logged; nothing attached. */
ob_result ob_window_attach(ob_window *w, ob_renderer *r);
/* Polls events; false once the window should close. */
bool ob_window_poll(ob_window *w);
/* True once per F1 press since the last call (without a listener). */
bool ob_window_take_toggle(ob_window *w);
/* Sends the window's input events to h (copied; NULL: none) from
 * ob_window_poll on. */
void ob_window_set_input(ob_window *w, const ob_input_handler *h);
/* The window's size in pixels (0x0 while minimised). */
void ob_window_size(ob_window *w, uint32_t *out_width, uint32_t *out_height);
/* Asks the window system for a new size, as a user dragging the border
 * would; the renderer follows once the window has it. */
void ob_window_request_size(ob_window *w, uint32_t width, uint32_t height);
/* Detaches the surface from the renderer (which waits idle), destroys it,
 * then the window. Call before ob_renderer_destroy. NULL is a no-op. */
void ob_window_close(ob_window *w);

#endif /* OB_WINDOW_H */
