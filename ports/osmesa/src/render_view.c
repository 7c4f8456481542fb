/* The renderer's GL-free setup: a view's defaults and the meshes' box. Kept
 * apart from gl_draw.c so that a program which only sets up views links no
 * GL library (the OSMesa context is loaded when a picture is drawn:
 * render.c). See afm/render.h. */
#include "afm/render.h"

#include <math.h>
#include <string.h>

#include "render_error.h"

void afm_render_view_init(afm_render_view *view, int width, int height) {
  memset(view, 0, sizeof *view);
  view->width = width;
  view->height = height;
  view->fov_deg = 25.0f;
  view->box_min[0] = 1.0f; /* min > max: frame all meshes */
  view->box_max[0] = -1.0f;
  view->margin = 0.06f;
  view->background[0] = view->background[1] = view->background[2] = 96;
  view->background[3] = 255;
  view->supersample = 2;
}

afm_result afm_render_bounds(const afm_render_mesh *meshes, size_t mesh_count,
                             float box_min[3], float box_max[3]) {
  size_t i, v;
  int k, any = 0;
  if (!meshes || !box_min || !box_max)
    return render_fail(AFM_ERR_ARGUMENT, "afm_render_bounds: NULL argument");
  for (k = 0; k < 3; ++k) {
    box_min[k] = HUGE_VALF;
    box_max[k] = -HUGE_VALF;
  }
  for (i = 0; i < mesh_count; ++i) {
    const float *p = meshes[i].positions;
    if (!p) continue;
    for (v = 0; v < meshes[i].vertex_count; ++v) {
      for (k = 0; k < 3; ++k) {
        float x = p[v * 3 + (size_t)k];
        if (x < box_min[k]) box_min[k] = x;
        if (x > box_max[k]) box_max[k] = x;
      }
      any = 1;
    }
  }
  if (!any) return render_fail(AFM_ERR_ARGUMENT, "no vertices to frame");
  return AFM_OK;
}
