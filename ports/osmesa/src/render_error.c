#include "render_error.h"

#include <stdarg.h>
#include <stdio.h>

#include "afm/render.h"

/* Per thread where the compiler offers it, so renderers on different
 * threads do not overwrite each other's messages. */
#if defined(__GNUC__)
static __thread char last_error[512];
#else
static char last_error[512];
#endif

afm_result render_fail(afm_result result, const char *format, ...) {
  va_list ap;
  va_start(ap, format);
  vsnprintf(last_error, sizeof last_error, format, ap);
  va_end(ap);
  return result;
}

void render_clear_error(void) { last_error[0] = '\0'; }

const char *afm_render_last_error(void) { return last_error; }
