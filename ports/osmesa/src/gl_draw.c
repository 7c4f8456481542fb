/* The renderer's OpenGL drawing, for whichever context is current: shaders,
 * camera, meshes. See afm/gl_draw.h. */
#define GL_GLEXT_PROTOTYPES 1

#include "afm/gl_draw.h"

#include <GL/gl.h>
#include <GL/glext.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render_error.h"

#define MAX_SIZE 8192
#define PI_F 3.14159265358979323846f

struct tex_entry {
  const uint8_t *src;
  int w, h;
  GLuint name;
  unsigned long used;  /* the call that last bound it */
  int kept;            /* uploaded as static: valid across calls */
};

#define TEX_KEEP 64 /* entries beyond this are recycled when not in use */

struct afm_gl_drawer {
  GLuint program;
  GLint u_lit, u_tex, u_sampler, u_bias, u_ortho, u_back, u_cut;
  /* Texture objects, one per distinct image (pixels pointer and size): an
   * image that several meshes share is uploaded once per frame, or once for
   * the drawer's life when its mesh says texture_static. */
  struct tex_entry *tex;
  size_t tex_count, tex_cap;
  unsigned long call; /* afm_gl_draw calls so far */
  float *normals; /* scratch for computed normals */
  size_t normals_cap;
};

/* ---- shaders ------------------------------------------------------------ */

/* Lights are fixed in eye space, so every view is lit the same way: a key
 * from the viewer's upper left, a fill from the right, and ambient. */
static const char *const vertex_src =
    "#version 120\n"
    "uniform float u_bias;\n"
    "uniform int u_ortho;\n"
    "varying vec3 v_n;\n"
    "varying vec3 v_p;\n"
    "varying vec4 v_c;\n"
    "varying vec2 v_uv;\n"
    "void main() {\n"
    "  vec4 eye = gl_ModelViewMatrix * gl_Vertex;\n"
    "  if (u_bias != 0.0) {\n"
    "    if (u_ortho != 0) eye.z += u_bias;\n"
    "    else eye.xyz *= max(1.0 - u_bias / length(eye.xyz), 0.0);\n"
    "  }\n"
    "  v_p = eye.xyz;\n"
    "  v_n = gl_NormalMatrix * gl_Normal;\n"
    "  v_c = gl_Color;\n"
    "  v_uv = vec2(gl_MultiTexCoord0.x, 1.0 - gl_MultiTexCoord0.y);\n"
    "  gl_Position = gl_ProjectionMatrix * eye;\n"
    "}\n";

static const char *const fragment_src =
    "#version 120\n"
    "uniform int u_lit;\n"
    "uniform int u_tex;\n"
    "uniform int u_ortho;\n"
    "uniform float u_back;\n"
    "uniform float u_cut;\n"
    "uniform sampler2D u_sampler;\n"
    "varying vec3 v_n;\n"
    "varying vec3 v_p;\n"
    "varying vec4 v_c;\n"
    "varying vec2 v_uv;\n"
    "void main() {\n"
    "  vec4 base = v_c;\n"
    "  if (u_tex != 0) base *= texture2D(u_sampler, v_uv);\n"
    "  if (base.a < u_cut) discard;\n"
    "  if (u_lit == 0) { gl_FragColor = base; return; }\n"
    "  vec3 n = normalize(v_n);\n"
    "  vec3 v = u_ortho != 0 ? vec3(0.0, 0.0, 1.0) : normalize(-v_p);\n"
    "  float shade = 1.0;\n"
    "  if (!gl_FrontFacing) { n = -n; shade = u_back; }\n"
    "  vec3 key = normalize(vec3(-0.45, 0.55, 0.70));\n"
    "  vec3 fill = normalize(vec3(0.80, 0.05, 0.60));\n"
    "  float d = 0.28 + 0.72 * max(dot(n, key), 0.0) + 0.28 * max(dot(n, fill), 0.0);\n"
    "  float s = 0.10 * pow(max(dot(n, normalize(key + v)), 0.0), 28.0);\n"
    "  gl_FragColor = vec4((base.rgb * d + vec3(s)) * shade, base.a);\n"
    "}\n";

static afm_result compile(GLenum kind, const char *src, GLuint *out) {
  GLuint sh = glCreateShader(kind);
  GLint ok = 0;
  char log[512];
  if (!sh) return render_fail(AFM_ERR_LIMIT, "OpenGL cannot create a shader");
  glShaderSource(sh, 1, &src, NULL);
  glCompileShader(sh);
  glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    log[0] = '\0';
    glGetShaderInfoLog(sh, (GLsizei)sizeof log, NULL, log);
    glDeleteShader(sh);
    return render_fail(AFM_ERR_LIMIT, "OpenGL rejects the %s shader: %s",
                       kind == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
  }
  *out = sh;
  return AFM_OK;
}

static afm_result build_program(afm_gl_drawer *r) {
  GLuint vs = 0, fs = 0, prog;
  GLint ok = 0;
  char log[512];
  afm_result res = compile(GL_VERTEX_SHADER, vertex_src, &vs);
  if (res != AFM_OK) return res;
  res = compile(GL_FRAGMENT_SHADER, fragment_src, &fs);
  if (res != AFM_OK) {
    glDeleteShader(vs);
    return res;
  }
  prog = glCreateProgram();
  glAttachShader(prog, vs);
  glAttachShader(prog, fs);
  glLinkProgram(prog);
  glDeleteShader(vs);
  glDeleteShader(fs);
  glGetProgramiv(prog, GL_LINK_STATUS, &ok);
  if (!ok) {
    log[0] = '\0';
    glGetProgramInfoLog(prog, (GLsizei)sizeof log, NULL, log);
    glDeleteProgram(prog);
    return render_fail(AFM_ERR_LIMIT, "OpenGL cannot link the shaders: %s", log);
  }
  r->program = prog;
  r->u_lit = glGetUniformLocation(prog, "u_lit");
  r->u_tex = glGetUniformLocation(prog, "u_tex");
  r->u_sampler = glGetUniformLocation(prog, "u_sampler");
  r->u_bias = glGetUniformLocation(prog, "u_bias");
  r->u_ortho = glGetUniformLocation(prog, "u_ortho");
  r->u_back = glGetUniformLocation(prog, "u_back");
  r->u_cut = glGetUniformLocation(prog, "u_cut");
  return AFM_OK;
}

/* ---- checks ------------------------------------------------------------- */

static afm_result check_mesh(const afm_render_mesh *m, size_t index) {
  size_t t;
  if (!m->positions || m->vertex_count == 0)
    return render_fail(AFM_ERR_ARGUMENT, "mesh %zu: no positions", index);
  if (m->vertex_count > 0xFFFFFFFFu)
    return render_fail(AFM_ERR_LIMIT, "mesh %zu: %zu vertices, more than 32-bit indices reach",
                       index, m->vertex_count);
  if (m->triangles) {
    for (t = 0; t < m->triangle_count * 3; ++t) {
      if (m->triangles[t] >= m->vertex_count)
        return render_fail(AFM_ERR_ARGUMENT, "mesh %zu: triangle %zu uses vertex %u of %zu",
                           index, t / 3, (unsigned)m->triangles[t], m->vertex_count);
    }
  }
  if (m->texture && m->uvs) {
    const afm_render_image *tex = m->texture;
    if (!tex->rgba || tex->width <= 0 || tex->height <= 0 || tex->width > MAX_SIZE ||
        tex->height > MAX_SIZE)
      return render_fail(AFM_ERR_ARGUMENT, "mesh %zu: texture without pixels or of size %dx%d",
                         index, tex->width, tex->height);
  }
  return AFM_OK;
}

/* ---- camera -------------------------------------------------------------- */

/* Column-major 4x4 matrices, as OpenGL loads them. */
typedef struct camera {
  float view[16];
  float proj[16];
  int ortho;
} camera;

static float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void setup_camera(const afm_render_view *view, const float bmin[3], const float bmax[3],
                         camera *cam) {
  float yaw = view->yaw_deg * PI_F / 180.0f, pitch = view->pitch_deg * PI_F / 180.0f;
  float fwd[3], right[3], up[3], centre[3], eye[3];
  float aspect = (float)view->width / (float)view->height;
  float margin = view->margin < 0.0f ? 0.0f : (view->margin > 0.45f ? 0.45f : view->margin);
  float fill = 1.0f - 2.0f * margin;
  float radius = 0.0f, ext_x = 0.0f, ext_y = 0.0f, dist = 0.0f, near_z, far_z;
  int c, k;
  for (k = 0; k < 3; ++k) centre[k] = 0.5f * (bmin[k] + bmax[k]);
  /* Direction from the target to the camera, then a right-handed basis. */
  fwd[0] = sinf(yaw) * cosf(pitch);
  fwd[1] = sinf(pitch);
  fwd[2] = cosf(yaw) * cosf(pitch);
  right[0] = cosf(yaw);
  right[1] = 0.0f;
  right[2] = -sinf(yaw);
  up[0] = fwd[1] * right[2] - fwd[2] * right[1];
  up[1] = fwd[2] * right[0] - fwd[0] * right[2];
  up[2] = fwd[0] * right[1] - fwd[1] * right[0];
  cam->ortho = view->fov_deg <= 0.0f;
  {
    float th = cam->ortho ? 1.0f : tanf(0.5f * view->fov_deg * PI_F / 180.0f);
    /* Fit every box corner: for a perspective camera at distance d a corner
     * at depth z toward the camera and offsets (x, y) needs
     * d >= z + |y| / th and d >= z + |x| / (th * aspect). */
    for (c = 0; c < 8; ++c) {
      float p[3], x, y, z;
      p[0] = ((c & 1) ? bmax[0] : bmin[0]) - centre[0];
      p[1] = ((c & 2) ? bmax[1] : bmin[1]) - centre[1];
      p[2] = ((c & 4) ? bmax[2] : bmin[2]) - centre[2];
      x = fabsf(dot3(p, right));
      y = fabsf(dot3(p, up));
      z = dot3(p, fwd);
      if (x > ext_x) ext_x = x;
      if (y > ext_y) ext_y = y;
      if (sqrtf(dot3(p, p)) > radius) radius = sqrtf(dot3(p, p));
      if (!cam->ortho) {
        float d1 = z + y / (th * fill), d2 = z + x / (th * aspect * fill);
        if (d1 > dist) dist = d1;
        if (d2 > dist) dist = d2;
      }
    }
  }
  if (radius <= 0.0f) radius = 1.0f;
  if (cam->ortho) dist = 3.0f * radius;
  if (dist < 1.05f * radius) dist = 1.05f * radius;
  if (view->zoom > 0.0f && !cam->ortho) dist /= view->zoom;
  for (k = 0; k < 3; ++k) eye[k] = centre[k] + dist * fwd[k];

  memset(cam->view, 0, sizeof cam->view);
  for (k = 0; k < 3; ++k) {
    cam->view[k * 4 + 0] = right[k];
    cam->view[k * 4 + 1] = up[k];
    cam->view[k * 4 + 2] = fwd[k];
  }
  cam->view[12] = -dot3(right, eye);
  cam->view[13] = -dot3(up, eye);
  cam->view[14] = -dot3(fwd, eye);
  cam->view[15] = 1.0f;

  near_z = dist - 1.5f * radius;
  if (near_z < 0.01f * dist) near_z = 0.01f * dist;
  far_z = dist + 1.5f * radius;
  memset(cam->proj, 0, sizeof cam->proj);
  if (cam->ortho) {
    float hh = ext_y / fill, hw = ext_x / fill;
    if (hw > hh * aspect) hh = hw / aspect;
    if (hh <= 0.0f) hh = 1.0f;
    if (view->zoom > 0.0f) hh /= view->zoom;
    cam->proj[0] = 1.0f / (hh * aspect);
    cam->proj[5] = 1.0f / hh;
    cam->proj[10] = -2.0f / (far_z - near_z);
    cam->proj[14] = -(far_z + near_z) / (far_z - near_z);
    cam->proj[15] = 1.0f;
  } else {
    float f = 1.0f / tanf(0.5f * view->fov_deg * PI_F / 180.0f);
    cam->proj[0] = f / aspect;
    cam->proj[5] = f;
    cam->proj[10] = (far_z + near_z) / (near_z - far_z);
    cam->proj[11] = -1.0f;
    cam->proj[14] = 2.0f * far_z * near_z / (near_z - far_z);
  }
}

/* ---- drawing ------------------------------------------------------------- */

static afm_result smooth_normals(afm_gl_drawer *r, const afm_render_mesh *m, const float **out) {
  size_t need = m->vertex_count * 3, t, v;
  const float *p = m->positions;
  if (need > r->normals_cap) {
    float *n = (float *)realloc(r->normals, need * sizeof(float));
    if (!n) return render_fail(AFM_ERR_OUT_OF_MEMORY, "out of memory for %zu normals", m->vertex_count);
    r->normals = n;
    r->normals_cap = need;
  }
  memset(r->normals, 0, need * sizeof(float));
  /* Unnormalised face normals summed: each face weighs by its area. */
  for (t = 0; t < m->triangle_count; ++t) {
    const uint32_t *f = m->triangles + t * 3;
    const float *a = p + (size_t)f[0] * 3, *b = p + (size_t)f[1] * 3, *c = p + (size_t)f[2] * 3;
    float e1[3], e2[3], n[3];
    int k, j;
    for (k = 0; k < 3; ++k) {
      e1[k] = b[k] - a[k];
      e2[k] = c[k] - a[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    for (j = 0; j < 3; ++j)
      for (k = 0; k < 3; ++k) r->normals[(size_t)f[j] * 3 + (size_t)k] += n[k];
  }
  for (v = 0; v < m->vertex_count; ++v) {
    float *n = r->normals + v * 3;
    float len = sqrtf(dot3(n, n));
    if (len > 0.0f) {
      n[0] /= len;
      n[1] /= len;
      n[2] /= len;
    } else {
      n[2] = 1.0f;
    }
  }
  *out = r->normals;
  return AFM_OK;
}

/* Binds the texture object holding `tex`, uploading it unless this call
 * already did, or it is static and was uploaded as static before. */
static afm_result bind_texture(afm_gl_drawer *r, const afm_render_image *tex, int is_static) {
  size_t i, pick = (size_t)-1;
  struct tex_entry *e;
  for (i = 0; i < r->tex_count; ++i)
    if (r->tex[i].src == tex->rgba && r->tex[i].w == tex->width && r->tex[i].h == tex->height) break;
  if (i < r->tex_count) {
    e = &r->tex[i];
    glBindTexture(GL_TEXTURE_2D, e->name);
    if (e->used == r->call || (is_static && e->kept)) {
      e->used = r->call;
      return AFM_OK;
    }
  } else {
    /* A new image: recycle the least recently used entry not bound in this
     * call once there are many, else add one. */
    if (r->tex_count >= TEX_KEEP)
      for (i = 0; i < r->tex_count; ++i)
        if (r->tex[i].used != r->call && (pick == (size_t)-1 || r->tex[i].used < r->tex[pick].used))
          pick = i;
    if (pick == (size_t)-1) {
      if (r->tex_count == r->tex_cap) {
        size_t cap = r->tex_cap ? 2 * r->tex_cap : 8;
        struct tex_entry *t = (struct tex_entry *)realloc(r->tex, cap * sizeof *t);
        if (!t) return render_fail(AFM_ERR_OUT_OF_MEMORY, "out of memory for %zu textures", cap);
        r->tex = t;
        r->tex_cap = cap;
      }
      pick = r->tex_count++;
      memset(&r->tex[pick], 0, sizeof r->tex[pick]);
      glGenTextures(1, &r->tex[pick].name);
    }
    e = &r->tex[pick];
    e->src = tex->rgba;
    e->w = tex->width;
    e->h = tex->height;
    glBindTexture(GL_TEXTURE_2D, e->name);
  }
  e->used = r->call;
  e->kept = is_static;
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA, tex->width, tex->height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               tex->rgba);
  glGenerateMipmap(GL_TEXTURE_2D);
  return AFM_OK;
}

static void set_color_state(const afm_render_mesh *m) {
  if (m->colors) {
    glEnableClientState(GL_COLOR_ARRAY);
    glColorPointer(4, GL_UNSIGNED_BYTE, 0, m->colors);
  } else {
    glDisableClientState(GL_COLOR_ARRAY);
    if (m->color[0] == 0.0f && m->color[1] == 0.0f && m->color[2] == 0.0f && m->color[3] == 0.0f)
      glColor4f(0.8f, 0.8f, 0.8f, 1.0f);
    else
      glColor4fv(m->color);
  }
}

static afm_result draw_mesh(afm_gl_drawer *r, const afm_render_mesh *m, const afm_render_view *view,
                            int scale) {
  int textured = m->texture && m->uvs && m->triangles;
  int lit = !m->unlit && m->triangles;
  glUniform1f(r->u_bias, m->depth_bias);
  glUniform1f(r->u_cut, m->alpha_cutoff);
  glEnableClientState(GL_VERTEX_ARRAY);
  glVertexPointer(3, GL_FLOAT, 0, m->positions);
  set_color_state(m);

  if (!m->triangles) {
    float size = (m->point_size > 0.0f ? m->point_size : 5.0f) * (float)scale;
    glUniform1i(r->u_lit, 0);
    glUniform1i(r->u_tex, 0);
    glDisableClientState(GL_NORMAL_ARRAY);
    glDisableClientState(GL_TEXTURE_COORD_ARRAY);
    glPointSize(size);
    glDrawArrays(GL_POINTS, 0, (GLsizei)m->vertex_count);
    return AFM_OK;
  }

  {
    const float *normals = m->normals;
    if (!normals) {
      afm_result res = smooth_normals(r, m, &normals);
      if (res != AFM_OK) return res;
    }
    glEnableClientState(GL_NORMAL_ARRAY);
    glNormalPointer(GL_FLOAT, 0, normals);
  }
  if (textured) {
    afm_result res;
    glActiveTexture(GL_TEXTURE0);
    res = bind_texture(r, m->texture, m->texture_static);
    if (res != AFM_OK) return res;
    glEnableClientState(GL_TEXTURE_COORD_ARRAY);
    glTexCoordPointer(2, GL_FLOAT, 0, m->uvs);
    glUniform1i(r->u_sampler, 0);
  } else {
    glDisableClientState(GL_TEXTURE_COORD_ARRAY);
  }
  glUniform1i(r->u_tex, textured);
  glUniform1i(r->u_lit, lit);

  if (m->wireframe) {
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);
  }
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glDrawElements(GL_TRIANGLES, (GLsizei)(m->triangle_count * 3), GL_UNSIGNED_INT, m->triangles);
  glDisable(GL_POLYGON_OFFSET_FILL);

  if (m->wireframe) {
    const float *wc = view->wire_color;
    glUniform1i(r->u_lit, 0);
    glUniform1i(r->u_tex, 0);
    glDisableClientState(GL_COLOR_ARRAY);
    if (wc[0] == 0.0f && wc[1] == 0.0f && wc[2] == 0.0f && wc[3] == 0.0f)
      glColor4f(0.15f, 0.15f, 0.15f, 1.0f);
    else
      glColor4fv(wc);
    glLineWidth((float)scale);
    glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    glDrawElements(GL_TRIANGLES, (GLsizei)(m->triangle_count * 3), GL_UNSIGNED_INT, m->triangles);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  }
  return AFM_OK;
}

/* ---- public: drawing ----------------------------------------------------- */

afm_result afm_gl_drawer_create(afm_gl_drawer **out) {
  afm_gl_drawer *r;
  afm_result res;
  if (!out) return render_fail(AFM_ERR_ARGUMENT, "afm_gl_drawer_create: out is NULL");
  *out = NULL;
  r = (afm_gl_drawer *)calloc(1, sizeof *r);
  if (!r) return render_fail(AFM_ERR_OUT_OF_MEMORY, "out of memory for the GL drawer");
  res = build_program(r);
  if (res != AFM_OK) {
    free(r);
    return res;
  }
  *out = r;
  return AFM_OK;
}

void afm_gl_drawer_destroy(afm_gl_drawer *r) {
  if (!r) return;
  free(r->tex);
  free(r->normals);
  free(r);
}

int afm_gl_supersample(const afm_render_view *view) {
  int s = view->supersample < 1 ? 1 : (view->supersample > 4 ? 4 : view->supersample);
  if (view->width * s > MAX_SIZE || view->height * s > MAX_SIZE) s = 1;
  return s;
}

afm_result afm_gl_draw(afm_gl_drawer *r, const afm_render_mesh *meshes, size_t mesh_count,
                       const afm_render_view *view, int s) {
  float bmin[3], bmax[3];
  camera cam;
  size_t i;
  int k;
  afm_result res;
  if (!r || !view || (!meshes && mesh_count))
    return render_fail(AFM_ERR_ARGUMENT, "afm_gl_draw: NULL argument");
  if (view->width <= 0 || view->height <= 0 || view->width > MAX_SIZE || view->height > MAX_SIZE)
    return render_fail(AFM_ERR_ARGUMENT, "image size %dx%d is not in 1..%d", view->width,
                       view->height, MAX_SIZE);
  if (s < 1 || s > 4 || view->width * s > MAX_SIZE || view->height * s > MAX_SIZE)
    return render_fail(AFM_ERR_ARGUMENT, "scale %d is not in 1..4 or makes the image larger than %d",
                       s, MAX_SIZE);
  for (i = 0; i < mesh_count; ++i) {
    res = check_mesh(&meshes[i], i);
    if (res != AFM_OK) return res;
  }
  if (view->box_min[0] <= view->box_max[0]) {
    for (k = 0; k < 3; ++k) {
      bmin[k] = view->box_min[k];
      bmax[k] = view->box_max[k];
    }
  } else if (mesh_count) {
    res = afm_render_bounds(meshes, mesh_count, bmin, bmax);
    if (res != AFM_OK) return res;
  } else {
    for (k = 0; k < 3; ++k) {
      bmin[k] = -1.0f;
      bmax[k] = 1.0f;
    }
  }
  r->call++;
  setup_camera(view, bmin, bmax, &cam);
  while (glGetError() != GL_NO_ERROR) {
    /* start from a clean slate: report only this frame's errors */
  }

  glViewport(0, 0, view->width * s, view->height * s);
  glClearColor(view->background[0] / 255.0f, view->background[1] / 255.0f,
               view->background[2] / 255.0f, view->background[3] / 255.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDisable(GL_CULL_FACE);
  glFrontFace(GL_CCW);
  glDisable(GL_BLEND);
  glMatrixMode(GL_PROJECTION);
  glLoadMatrixf(cam.proj);
  glMatrixMode(GL_MODELVIEW);
  glLoadMatrixf(cam.view);
  glUseProgram(r->program);
  glUniform1i(r->u_ortho, cam.ortho);
  glUniform1f(r->u_back, 0.35f);

  for (i = 0; i < mesh_count; ++i) {
    res = draw_mesh(r, &meshes[i], view, s);
    if (res != AFM_OK) return res;
  }
  glFinish();
  if (glGetError() != GL_NO_ERROR) {
    /* Drawing errors are ours (a state we set wrongly), not the caller's. */
    return render_fail(AFM_ERR_LIMIT, "OpenGL reported an error while drawing");
  }
  return AFM_OK;
}

void afm_gl_resolve(const uint8_t *gl_rgba, int w, int h, int s, uint8_t *out) {
  int x, y, i, j, k;
  unsigned n = (unsigned)(s * s);
  size_t stride = (size_t)w * (size_t)s * 4;
  for (y = 0; y < h; ++y) {
    for (x = 0; x < w; ++x) {
      unsigned acc[4] = {0, 0, 0, 0};
      for (j = 0; j < s; ++j) {
        const uint8_t *row = gl_rgba + ((size_t)(h - 1 - y) * (size_t)s + (size_t)(s - 1 - j)) * stride;
        for (i = 0; i < s; ++i)
          for (k = 0; k < 4; ++k) acc[k] += row[((size_t)x * (size_t)s + (size_t)i) * 4 + (size_t)k];
      }
      for (k = 0; k < 4; ++k)
        out[((size_t)y * (size_t)w + (size_t)x) * 4 + (size_t)k] = (uint8_t)((acc[k] + n / 2) / n);
    }
  }
}
