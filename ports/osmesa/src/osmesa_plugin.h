/* Internal: the interface between afm/render.h's renderer (render.c, linked
 * into every program that renders) and the OSMesa context behind it
 * (osmesa_plugin.c with gl_draw.c, built as the shared object
 * libafm_osmesa.so and loaded on the first afm_renderer_create).
 *
 * Why a shared object: libOSMesa brings libLLVM, whose relocations cost a
 * program about 0.06 s at every start, pictures or not (afm-build without
 * --report, afm-headgen without --render). Loaded when a picture is asked for,
 * only the programs that draw pay it.
 *
 * The object exports one symbol, AFM_OSMESA_PLUGIN_ENTRY, a function that
 * returns a static table. Both sides are built from the same headers; the
 * table's version and the sizes of the structs it passes catch an object
 * left from another build. */
#ifndef AFM_OSMESA_PLUGIN_H
#define AFM_OSMESA_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#include "afm/render.h"

#define AFM_OSMESA_PLUGIN_VERSION 1
#define AFM_OSMESA_PLUGIN_ENTRY "afm_osmesa_plugin_get"
#define AFM_OSMESA_PLUGIN_FILE "libafm_osmesa.so"

typedef struct afm_osmesa_plugin {
  int version;       /* AFM_OSMESA_PLUGIN_VERSION */
  size_t mesh_size;  /* sizeof(afm_render_mesh) */
  size_t view_size;  /* sizeof(afm_render_view) */
  /* afm/render.h's functions of the same names; the object keeps its own
   * last-error text, which last_error() gives after a failure. */
  afm_result (*renderer_create)(afm_renderer **out);
  void (*renderer_destroy)(afm_renderer *renderer);
  afm_result (*renderer_draw)(afm_renderer *renderer, const afm_render_mesh *meshes,
                              size_t mesh_count, const afm_render_view *view, uint8_t *rgba_out);
  const char *(*last_error)(void);
} afm_osmesa_plugin;

typedef const afm_osmesa_plugin *(*afm_osmesa_plugin_fn)(void);

#endif
