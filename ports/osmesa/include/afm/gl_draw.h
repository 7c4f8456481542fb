/* Drawing afm_render_mesh lists with the current OpenGL context: the
 * renderer's shaders, camera, lighting, textures and wireframe, shared by the
 * offscreen renderer (afm_renderer, OSMesa) and the desktop preview
 * (ports/glfw, a GLFW window), so both draw the same picture.
 *
 * This code calls OpenGL 2.1 with GLSL 1.20 in a compatibility context and
 * binds to whichever GL library it is linked with: libOSMesa (inside the
 * renderer's shared object, libafm_osmesa.so) or libGL (afm-view); never
 * both in one object, since each defines the gl* functions.
 *
 * Meshes, views and their conventions: afm/render.h. Errors: afm_result, and
 * afm_render_last_error() explains.
 */
#ifndef AFM_GL_DRAW_H
#define AFM_GL_DRAW_H

#include <stddef.h>
#include <stdint.h>

#include "afm/render.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The shader program and the texture objects of one GL context. */
typedef struct afm_gl_drawer afm_gl_drawer;

/* Compiles the shaders in the current context. AFM_ERR_LIMIT when the
 * context cannot compile or link them (the message holds GL's log). */
afm_result afm_gl_drawer_create(afm_gl_drawer **out);
/* Frees the drawer's memory. Its program and textures belong to the GL
 * context and go with it: destroy the context too (or keep using it with a
 * new drawer, at the cost of those objects). NULL is fine. */
void afm_gl_drawer_destroy(afm_gl_drawer *drawer);

/* The supersampling factor a view asks for, clamped to 1..4 (and 1 when the
 * enlarged image would exceed 8192 pixels). */
int afm_gl_supersample(const afm_render_view *view);

/* Checks the meshes and view, then clears and draws into the framebuffer
 * bound now, over a viewport of (view->width * scale) x (view->height *
 * scale) pixels at its origin; `scale` (1..4) also widens lines and points.
 * Waits for GL to finish. AFM_ERR_ARGUMENT for bad meshes or sizes,
 * AFM_ERR_OUT_OF_MEMORY, AFM_ERR_LIMIT when GL reports an error. */
afm_result afm_gl_draw(afm_gl_drawer *drawer, const afm_render_mesh *meshes, size_t mesh_count,
                       const afm_render_view *view, int scale);

/* Box-filters a GL image `scale` times larger than width x height (bottom
 * row first, rows of width * scale * 4 bytes, as glReadPixels and OSMesa
 * give it) into a width x height RGBA8 image, top row first. */
void afm_gl_resolve(const uint8_t *gl_rgba, int width, int height, int scale, uint8_t *rgba_out);

#ifdef __cplusplus
}
#endif

#endif /* AFM_GL_DRAW_H */
