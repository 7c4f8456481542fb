/* afm/render.h's renderer: loads the OSMesa context (libafm_osmesa.so,
 * osmesa_plugin.h says why) on the first afm_renderer_create and forwards to
 * it. A program that never draws never maps libOSMesa or libLLVM. */
#define _GNU_SOURCE 1 /* readlink and dlopen under -std=c99 */

#include "afm/render.h"

#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "osmesa_plugin.h"
#include "render_error.h"

#ifndef PATH_MAX
#define PATH_MAX 4096
#endif

static pthread_once_t load_once = PTHREAD_ONCE_INIT;
static const afm_osmesa_plugin *plugin;
static afm_result load_result;
static char load_error[PATH_MAX + 512];

/* Opens `path` and checks its table; on failure, says why in load_error.
 * `hint`: how to point the loader elsewhere, for a file it could not open. */
static const afm_osmesa_plugin *open_plugin(const char *path, const char *hint,
                                            afm_result *result) {
  /* RTLD_LOCAL: the object's GL symbols stay its own. Never closed: OSMesa
   * keeps state for the process, and the sanitizers symbolise its frames. */
  void *handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  afm_osmesa_plugin_fn entry;
  const afm_osmesa_plugin *table;
  const char *why;
  if (!handle) {
    why = dlerror(); /* glibc's names the file */
    *result = AFM_ERR_IO;
    snprintf(load_error, sizeof load_error, "cannot load the OSMesa renderer: %s%s",
             why ? why : path, hint);
    return NULL;
  }
  /* POSIX's sanctioned way from a data pointer to a function pointer. */
  *(void **)&entry = dlsym(handle, AFM_OSMESA_PLUGIN_ENTRY);
  table = entry ? entry() : NULL;
  if (!table) {
    *result = AFM_ERR_VERSION;
    snprintf(load_error, sizeof load_error,
             "%s is not the AFM OSMesa renderer (it has no %s)", path, AFM_OSMESA_PLUGIN_ENTRY);
  } else if (table->version != AFM_OSMESA_PLUGIN_VERSION ||
             table->mesh_size != sizeof(afm_render_mesh) ||
             table->view_size != sizeof(afm_render_view)) {
    *result = AFM_ERR_VERSION;
    snprintf(load_error, sizeof load_error,
             "the OSMesa renderer %s is from another build (version %d, expected %d): "
             "rebuild or reinstall it",
             path, table->version, AFM_OSMESA_PLUGIN_VERSION);
  } else {
    return table;
  }
  dlclose(handle);
  return NULL;
}

/* Where to look: $AFM_OSMESA_PLUGIN when set; else beside the program's own
 * directory, in ../lib (the build tree's bin/, tests/ and bench/, and an
 * installed prefix's bin/ all sit next to lib/); else the dynamic loader's
 * search path. */
static void load_plugin(void) {
  char path[PATH_MAX + 64];
  const char *env = getenv("AFM_OSMESA_PLUGIN");
  ssize_t n;
  char *slash;
  if (env && env[0]) {
    plugin = open_plugin(env, "", &load_result);
    return;
  }
  n = readlink("/proc/self/exe", path, PATH_MAX);
  if (n > 0 && n < PATH_MAX) {
    path[n] = '\0';
    slash = strrchr(path, '/');
    if (slash) {
      strcpy(slash + 1, "../lib/" AFM_OSMESA_PLUGIN_FILE);
      if (access(path, F_OK) == 0) {
        plugin = open_plugin(path, "", &load_result);
        return;
      }
    }
  }
  plugin = open_plugin(AFM_OSMESA_PLUGIN_FILE,
                       " (not in ../lib beside the program either: set AFM_OSMESA_PLUGIN to "
                       "its path)",
                       &load_result);
}

static afm_result need_plugin(void) {
  pthread_once(&load_once, load_plugin);
  if (!plugin) return render_fail(load_result, "%s", load_error);
  return AFM_OK;
}

/* A failure inside the object: its message, in this side's last error. */
static afm_result forward_failure(afm_result result) {
  if (result != AFM_OK) render_fail(result, "%s", plugin->last_error());
  return result;
}

afm_result afm_renderer_create(afm_renderer **out) {
  afm_result res;
  render_clear_error();
  if (!out) return render_fail(AFM_ERR_ARGUMENT, "afm_renderer_create: out is NULL");
  *out = NULL;
  res = need_plugin();
  if (res != AFM_OK) return res;
  return forward_failure(plugin->renderer_create(out));
}

void afm_renderer_destroy(afm_renderer *r) {
  /* A renderer exists only when the object loaded. */
  if (r) plugin->renderer_destroy(r);
}

afm_result afm_renderer_draw(afm_renderer *r, const afm_render_mesh *meshes, size_t mesh_count,
                             const afm_render_view *view, uint8_t *rgba_out) {
  render_clear_error();
  if (!r) return render_fail(AFM_ERR_ARGUMENT, "afm_renderer_draw: NULL argument");
  return forward_failure(plugin->renderer_draw(r, meshes, mesh_count, view, rgba_out));
}

afm_result afm_render(const afm_render_mesh *meshes, size_t mesh_count,
                      const afm_render_view *view, uint8_t *rgba_out) {
  afm_renderer *r = NULL;
  afm_result res = afm_renderer_create(&r);
  if (res != AFM_OK) return res;
  res = afm_renderer_draw(r, meshes, mesh_count, view, rgba_out);
  afm_renderer_destroy(r);
  return res;
}

/* Mesa's OSMesa (22.x) keeps a few hundred bytes per context that
 * OSMesaDestroyContext does not free (its framebuffer list). LeakSanitizer
 * (the sanitize build) reads its default suppressions from this hook, which
 * must be in the program, not in the loaded object: so every program that
 * renders gets it. Weak, so a program can define its own. Harmless without
 * the sanitizers. */
#if defined(__GNUC__)
const char *__lsan_default_suppressions(void) __attribute__((weak));
const char *__lsan_default_suppressions(void) { return "leak:libOSMesa.so\n"; }
#endif
