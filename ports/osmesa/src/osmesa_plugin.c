/* Offscreen mesh rendering through OSMesa (software OpenGL 2.1+ with GLSL
 * 1.20 in a compatibility context): the context and its buffer. The drawing
 * itself is gl_draw.c, shared with the desktop preview. Built into
 * libafm_osmesa.so, which render.c loads on the first renderer: see
 * osmesa_plugin.h. */
#include "osmesa_plugin.h"

#include <GL/gl.h>
#include <GL/osmesa.h>
#include <stdlib.h>

#include "afm/gl_draw.h"
#include "render_error.h"

struct afm_renderer {
  OSMesaContext ctx;
  uint8_t *buffer; /* (width * s) x (height * s) RGBA, bottom row first */
  int buf_w, buf_h;
  afm_gl_drawer *drawer; /* made on the first draw, with the context current */
};

static afm_result osmesa_create(afm_renderer **out) {
  afm_renderer *r;
  render_clear_error();
  if (!out) return render_fail(AFM_ERR_ARGUMENT, "afm_renderer_create: out is NULL");
  *out = NULL;
  r = (afm_renderer *)calloc(1, sizeof *r);
  if (!r) return render_fail(AFM_ERR_OUT_OF_MEMORY, "out of memory for the renderer");
  r->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
  if (!r->ctx) {
    free(r);
    return render_fail(AFM_ERR_LIMIT, "OSMesa cannot create an RGBA context with a 24-bit depth buffer");
  }
  *out = r;
  return AFM_OK;
}

static void osmesa_destroy(afm_renderer *r) {
  if (!r) return;
  /* Unbind first: Mesa keeps the framebuffer of a context that is still
   * current when it is destroyed. The shader program and textures belong to
   * the context and go with it. */
  if (OSMesaGetCurrentContext() == r->ctx) OSMesaMakeCurrent(NULL, NULL, GL_UNSIGNED_BYTE, 0, 0);
  OSMesaDestroyContext(r->ctx);
  afm_gl_drawer_destroy(r->drawer);
  free(r->buffer);
  free(r);
}

static afm_result ensure_buffer(afm_renderer *r, int w, int h) {
  GLint maxw = 0, maxh = 0;
  if (w != r->buf_w || h != r->buf_h) {
    uint8_t *b = (uint8_t *)realloc(r->buffer, (size_t)w * (size_t)h * 4);
    if (!b) return render_fail(AFM_ERR_OUT_OF_MEMORY, "out of memory for a %dx%d image", w, h);
    r->buffer = b;
    r->buf_w = w;
    r->buf_h = h;
  }
  if (!OSMesaMakeCurrent(r->ctx, r->buffer, GL_UNSIGNED_BYTE, w, h))
    return render_fail(AFM_ERR_LIMIT, "OSMesa cannot render a %dx%d image", w, h);
  OSMesaGetIntegerv(OSMESA_MAX_WIDTH, &maxw);
  OSMesaGetIntegerv(OSMESA_MAX_HEIGHT, &maxh);
  if ((maxw > 0 && w > maxw) || (maxh > 0 && h > maxh))
    return render_fail(AFM_ERR_LIMIT, "a %dx%d image is larger than OSMesa's %dx%d", w, h,
                       (int)maxw, (int)maxh);
  if (!r->drawer) return afm_gl_drawer_create(&r->drawer);
  return AFM_OK;
}

static afm_result osmesa_draw(afm_renderer *r, const afm_render_mesh *meshes, size_t mesh_count,
                              const afm_render_view *view, uint8_t *rgba_out) {
  int s;
  afm_result res;
  render_clear_error();
  if (!r || !view || !rgba_out || (!meshes && mesh_count))
    return render_fail(AFM_ERR_ARGUMENT, "afm_renderer_draw: NULL argument");
  if (view->width <= 0 || view->height <= 0 || view->width > 8192 || view->height > 8192)
    return render_fail(AFM_ERR_ARGUMENT, "image size %dx%d is not in 1..%d", view->width,
                       view->height, 8192);
  s = afm_gl_supersample(view);
  res = ensure_buffer(r, view->width * s, view->height * s);
  if (res != AFM_OK) return res;
  res = afm_gl_draw(r->drawer, meshes, mesh_count, view, s);
  if (res != AFM_OK) return res;
  afm_gl_resolve(r->buffer, view->width, view->height, s, rgba_out);
  return AFM_OK;
}

/* The object's one exported symbol (it is built with hidden visibility). */
#if defined(__GNUC__)
__attribute__((visibility("default")))
#endif
const afm_osmesa_plugin *afm_osmesa_plugin_get(void);

const afm_osmesa_plugin *afm_osmesa_plugin_get(void) {
  static const afm_osmesa_plugin table = {
      AFM_OSMESA_PLUGIN_VERSION, sizeof(afm_render_mesh), sizeof(afm_render_view),
      osmesa_create, osmesa_destroy, osmesa_draw, afm_render_last_error};
  return &table;
}
