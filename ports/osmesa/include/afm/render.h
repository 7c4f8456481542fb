/* Offscreen rendering of triangle meshes to RGBA images and PNG files.
 *
 * The core of the project's pictures: the reference head, faces before and
 * after building, animation frames. C99 over OSMesa (software OpenGL, no
 * display needed) and libpng.
 *
 * A frame is a list of meshes (afm_render_mesh) seen through one view
 * (afm_render_view). Every array is caller-owned and only read during the
 * call. The image written is RGBA8, top row first, width * height * 4 bytes,
 * also caller-owned. The OpenGL drawing itself is afm/gl_draw.h, which the
 * desktop preview (ports/glfw) shares.
 *
 * Frame of reference: the MPEG-4 neutral frame, +x the face's own left, +y
 * up, +z forward (toward the viewer at yaw = pitch = 0). The camera looks at
 * the centre of a framing box from the front, turned by yaw (degrees,
 * positive: the camera moves toward +x, so the face's left cheek turns
 * toward the viewer) and pitch (positive: the camera moves up and looks
 * down), and stands far enough for the whole box to fit the image.
 *
 * Shading: smooth (per-pixel) lighting with a key light from the upper left
 * of the viewer, a weaker fill from the right and an ambient term; back faces
 * (the inside of an open mesh, seen through a hole) are drawn darker.
 *
 * The OSMesa context lives in a shared object, libafm_osmesa.so, which the
 * first afm_renderer_create (or afm_render) loads, so that a program that
 * draws nothing never maps libOSMesa and the libLLVM it brings (0.06 s at
 * every start). It is looked for at $AFM_OSMESA_PLUGIN when that is set,
 * else in ../lib beside the program's own directory (the build tree and an
 * installed prefix), else on the dynamic loader's search path. Loading is
 * thread-safe and happens once; the object stays loaded.
 *
 * Errors: every fallible function returns an afm_result from afm/format.h:
 * AFM_ERR_ARGUMENT for a NULL or inconsistent argument (an index out of
 * range, a zero size), AFM_ERR_OUT_OF_MEMORY, AFM_ERR_IO for a file that
 * cannot be written or a libafm_osmesa.so that cannot be loaded,
 * AFM_ERR_VERSION for a shared object that is not this build's renderer,
 * AFM_ERR_LIMIT when OSMesa cannot provide a context of that size.
 * afm_render_last_error() gives a one-line explanation.
 */
#ifndef AFM_RENDER_H
#define AFM_RENDER_H

#include <stddef.h>
#include <stdint.h>

#include "afm/format.h"

#ifdef __cplusplus
extern "C" {
#endif

/* An RGBA8 image, top row first, rows packed (stride = width * 4). */
typedef struct afm_render_image {
  const uint8_t *rgba;
  int width;
  int height;
} afm_render_image;

/* One mesh of a frame. Zero-initialise, then fill in what you have. */
typedef struct afm_render_mesh {
  const float *positions;     /* vertex_count x 3, required */
  size_t vertex_count;
  const uint32_t *triangles;  /* triangle_count x 3 (0-based, counter-clockwise
                                 seen from outside), or NULL: the vertices are
                                 drawn as square dots of point_size pixels */
  size_t triangle_count;
  const float *normals;       /* vertex_count x 3, or NULL: computed smooth
                                 (area-weighted) from the triangles */
  const uint8_t *colors;      /* vertex_count x 4 RGBA8, or NULL: `color` */
  const float *uvs;           /* vertex_count x 2 (per vertex, v up), or NULL */
  const afm_render_image *texture; /* modulates the colour when uvs are given */
  int texture_static;         /* non-zero: the texture's pixels stay as they are
                                 for the renderer's life (while this pointer and
                                 size are used), so an afm_renderer uploads them
                                 once instead of at every draw */
  float color[4];             /* material RGBA in [0,1] used when colors is NULL;
                                 all zero means light grey */
  int wireframe;              /* non-zero: draw the triangle edges over the faces */
  int unlit;                  /* non-zero: flat colour, no lighting (markers) */
  float point_size;           /* dot size in pixels when triangles is NULL (0: 5) */
  float depth_bias;           /* pulls the mesh toward the viewer by this many
                                 model units, so markers lying on a surface are
                                 not hidden by it; 0 for ordinary meshes */
  float alpha_cutoff;         /* pixels whose alpha (colour times texture) is
                                 below this are not drawn: cut-out textures such
                                 as hair strands and lashes; 0 draws every pixel
                                 (alpha is otherwise ignored: no blending) */
} afm_render_mesh;

/* Where the camera is and what the image looks like. Zero-initialise, then
 * set width and height; afm_render_view_init() gives sensible values. */
typedef struct afm_render_view {
  int width, height;          /* pixels, 1..8192 */
  float yaw_deg, pitch_deg;   /* see the header comment */
  float fov_deg;              /* vertical field of view; 0 = orthographic */
  float box_min[3], box_max[3]; /* framing box in model units; when
                                   box_min[0] > box_max[0] the box of all
                                   meshes is used */
  float margin;               /* fraction of the image left around the box (0..0.45) */
  uint8_t background[4];      /* RGBA */
  int supersample;            /* 1..4: render s times larger and average (anti-aliasing) */
  float wire_color[4];        /* wireframe RGBA; all zero means dark grey */
  float zoom;                 /* > 1 moves the camera closer (its distance, or an
                                 orthographic view's extent, divided by zoom),
                                 < 1 away; 0 means 1: the box just fits */
} afm_render_view;

/* Width x height, front view, 25 degree lens, box from the meshes, 6 %
 * margin, mid-grey background, 2x supersampling. */
void afm_render_view_init(afm_render_view *view, int width, int height);

/* A reusable rendering context: keeps the OSMesa context and buffers between
 * frames of the same size (an animation renders many). Creating the first
 * one loads libafm_osmesa.so (see the header comment). */
typedef struct afm_renderer afm_renderer;

afm_result afm_renderer_create(afm_renderer **out);
void afm_renderer_destroy(afm_renderer *renderer);

/* Renders the meshes into rgba_out (view->width * view->height * 4 bytes). */
afm_result afm_renderer_draw(afm_renderer *renderer, const afm_render_mesh *meshes,
                             size_t mesh_count, const afm_render_view *view,
                             uint8_t *rgba_out);

/* One frame without keeping a renderer: create, draw, destroy. */
afm_result afm_render(const afm_render_mesh *meshes, size_t mesh_count,
                      const afm_render_view *view, uint8_t *rgba_out);

/* The box of all the meshes' positions; AFM_ERR_ARGUMENT when there are none. */
afm_result afm_render_bounds(const afm_render_mesh *meshes, size_t mesh_count,
                             float box_min[3], float box_max[3]);

/* Writes an RGBA8 image as an 8-bit RGBA PNG. Atomic: a temporary file
 * beside `path` is renamed over it, so `path` is complete or untouched. */
afm_result afm_png_write(const char *path, const afm_render_image *image);

/* Tiles `count` images left to right, top to bottom, `columns` per row, with
 * `gap` pixels of `background` between and around them, into one image.
 * Tiles may differ in size: each sits at the top-left of a cell as large as
 * the largest tile. afm_sheet_size() gives the sheet's size;
 * afm_sheet_compose() fills a caller-owned buffer of that size;
 * afm_sheet_write_png() composes and writes in one step. */
afm_result afm_sheet_size(const afm_render_image *tiles, int count, int columns, int gap,
                          int *width, int *height);
afm_result afm_sheet_compose(const afm_render_image *tiles, int count, int columns, int gap,
                             const uint8_t background[4], uint8_t *rgba_out);
afm_result afm_sheet_write_png(const char *path, const afm_render_image *tiles, int count,
                               int columns, int gap, const uint8_t background[4]);

/* Explanation of the last failure in this thread's most recent call, e.g.
 * "mesh 2: triangle 17 uses vertex 900 of 850". Never NULL. */
const char *afm_render_last_error(void);

#ifdef __cplusplus
}
#endif

#endif /* AFM_RENDER_H */
