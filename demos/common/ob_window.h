/* ob_window.h — a GLFW window that shows a demo's final image live.
 *
 * Built when GLFW is found (libglfw3-dev; -DOB_WITH_WINDOW=OFF leaves it out;
 * headless builds keep these functions, which then say so). The window is created
 * before the renderer (the instance needs its surface extensions), the
 * swapchain after it. Each frame, ob_window_present blits the final target
 * into the acquired swapchain image in its own small submission after the
 * renderer's, and presents. F1 asks the demo to toggle single/multi-threaded
 * recording; closing the window or Escape ends the loop.
 *
 * Thread rule: render thread only (GLFW's main-thread rule).
 */
#ifndef OB_WINDOW_H
#define OB_WINDOW_H

#include "ob_resources.h"

typedef struct ob_window ob_window;

/* Opens a window; NULL with a message when there is no display or GLFW
 * cannot start. *out_exts / *out_ext_count: the instance extensions the
 * device must enable (owned by GLFW). */
ob_window *ob_window_open(uint32_t width, uint32_t height, const char *title,
                          const char *const **out_exts, uint32_t *out_ext_count);
/* Surface and swapchain on the renderer's device. */
ob_result ob_window_attach(ob_window *w, ob_device *dev);
/* Polls events; false once the window should close. */
bool ob_window_poll(ob_window *w);
/* True once per F1 press since the last call. */
bool ob_window_take_toggle(ob_window *w);
/* Blit `image` (the final target) to the window and present. A frame the
 * swapchain cannot take (out of date, e.g. minimised) is skipped, not an error. */
ob_result ob_window_present(ob_window *w, ob_image image);
/* Frames presented so far, and frames skipped because the swapchain was out
 * of date. */
uint32_t ob_window_presented(const ob_window *w, uint32_t *out_skipped);
/* Waits for its own work, destroys the swapchain, surface and window. */
void ob_window_close(ob_window *w);

#endif /* OB_WINDOW_H */
