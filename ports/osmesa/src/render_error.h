/* Internal: the last-error text behind afm_render_last_error(). */
#ifndef AFM_RENDER_ERROR_H
#define AFM_RENDER_ERROR_H

#include "afm/format.h"

/* Formats the message (printf-style) and returns `result`, so a failure
 * reads `return render_fail(AFM_ERR_ARGUMENT, "mesh %zu: ...", i);`. */
afm_result render_fail(afm_result result, const char *format, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;
void render_clear_error(void);

#endif
