/* PNG output (libpng) and contact sheets. See afm/render.h. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "afm/render.h"
#include "render_error.h"

#define MAX_SIZE 65535

static afm_result check_image(const afm_render_image *im, const char *what, int index) {
  if (!im || !im->rgba || im->width <= 0 || im->height <= 0 || im->width > MAX_SIZE ||
      im->height > MAX_SIZE)
    return render_fail(AFM_ERR_ARGUMENT, "%s %d: no pixels or size %dx%d out of 1..%d", what,
                       index, im ? im->width : 0, im ? im->height : 0, MAX_SIZE);
  return AFM_OK;
}

/* Encodes into an open file. libpng reports errors by longjmp; everything
 * that needs freeing is created before the setjmp. */
static int encode(FILE *f, const afm_render_image *image, png_bytep *rows) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
  png_infop info;
  int h;
  if (!png) return 0;
  info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, NULL);
    return 0;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return 0;
  }
  for (h = 0; h < image->height; ++h)
    rows[h] = (png_bytep)(image->rgba + (size_t)h * (size_t)image->width * 4);
  png_init_io(png, f);
  png_set_IHDR(png, info, (png_uint_32)image->width, (png_uint_32)image->height, 8,
               PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  /* zlib level 3: about three times faster than the default (6) on rendered
   * frames, for files some 15 % larger; animations write many. */
  png_set_compression_level(png, 3);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, NULL);
  png_destroy_write_struct(&png, &info);
  return 1;
}

afm_result afm_png_write(const char *path, const afm_render_image *image) {
  char *tmp;
  FILE *f;
  png_bytep *rows;
  int ok;
  size_t len;
  afm_result res;
  render_clear_error();
  if (!path || !*path) return render_fail(AFM_ERR_ARGUMENT, "afm_png_write: no path");
  res = check_image(image, "image", 0);
  if (res != AFM_OK) return res;
  rows = (png_bytep *)malloc((size_t)image->height * sizeof *rows);
  len = strlen(path) + 32;
  tmp = (char *)malloc(len);
  if (!rows || !tmp) {
    free(rows);
    free(tmp);
    return render_fail(AFM_ERR_OUT_OF_MEMORY, "out of memory writing %s", path);
  }
  /* Beside the target, so the rename stays on one file system. */
  snprintf(tmp, len, "%s.tmp.%ld", path, (long)getpid());
  f = fopen(tmp, "wb");
  if (!f) {
    int e = errno;
    free(rows);
    free(tmp);
    return render_fail(AFM_ERR_IO, "%s: cannot create: %s", path, strerror(e));
  }
  ok = encode(f, image, rows);
  ok = (fflush(f) == 0) && ok;
  ok = (fclose(f) == 0) && ok;
  free(rows);
  if (!ok) {
    remove(tmp);
    free(tmp);
    return render_fail(AFM_ERR_IO, "%s: writing the PNG failed", path);
  }
  if (rename(tmp, path) != 0) {
    int e = errno;
    remove(tmp);
    free(tmp);
    return render_fail(AFM_ERR_IO, "%s: cannot rename into place: %s", path, strerror(e));
  }
  free(tmp);
  return AFM_OK;
}

/* ---- contact sheets ----------------------------------------------------- */

afm_result afm_sheet_size(const afm_render_image *tiles, int count, int columns, int gap,
                          int *width, int *height) {
  int i, cell_w = 0, cell_h = 0, rows;
  long long w, h;
  afm_result res;
  render_clear_error();
  if (!tiles || count <= 0 || columns <= 0 || gap < 0 || !width || !height)
    return render_fail(AFM_ERR_ARGUMENT,
                       "contact sheet: need tiles, count > 0, columns > 0 and gap >= 0");
  for (i = 0; i < count; ++i) {
    res = check_image(&tiles[i], "tile", i);
    if (res != AFM_OK) return res;
    if (tiles[i].width > cell_w) cell_w = tiles[i].width;
    if (tiles[i].height > cell_h) cell_h = tiles[i].height;
  }
  if (columns > count) columns = count;
  rows = (count + columns - 1) / columns;
  w = (long long)columns * cell_w + (long long)(columns + 1) * gap;
  h = (long long)rows * cell_h + (long long)(rows + 1) * gap;
  if (w > MAX_SIZE || h > MAX_SIZE)
    return render_fail(AFM_ERR_LIMIT, "contact sheet of %lldx%lld pixels is too large", w, h);
  *width = (int)w;
  *height = (int)h;
  return AFM_OK;
}

afm_result afm_sheet_compose(const afm_render_image *tiles, int count, int columns, int gap,
                             const uint8_t background[4], uint8_t *rgba_out) {
  int w, h, i, y, cell_w = 0, cell_h = 0;
  size_t p;
  afm_result res = afm_sheet_size(tiles, count, columns, gap, &w, &h);
  if (res != AFM_OK) return res;
  if (!rgba_out || !background) return render_fail(AFM_ERR_ARGUMENT, "contact sheet: NULL buffer");
  if (columns > count) columns = count;
  for (i = 0; i < count; ++i) {
    if (tiles[i].width > cell_w) cell_w = tiles[i].width;
    if (tiles[i].height > cell_h) cell_h = tiles[i].height;
  }
  for (p = 0; p < (size_t)w * (size_t)h; ++p) memcpy(rgba_out + p * 4, background, 4);
  for (i = 0; i < count; ++i) {
    int x0 = gap + (i % columns) * (cell_w + gap);
    int y0 = gap + (i / columns) * (cell_h + gap);
    for (y = 0; y < tiles[i].height; ++y)
      memcpy(rgba_out + ((size_t)(y0 + y) * (size_t)w + (size_t)x0) * 4,
             tiles[i].rgba + (size_t)y * (size_t)tiles[i].width * 4, (size_t)tiles[i].width * 4);
  }
  return AFM_OK;
}

afm_result afm_sheet_write_png(const char *path, const afm_render_image *tiles, int count,
                               int columns, int gap, const uint8_t background[4]) {
  int w, h;
  uint8_t *buf;
  afm_render_image sheet;
  afm_result res = afm_sheet_size(tiles, count, columns, gap, &w, &h);
  if (res != AFM_OK) return res;
  buf = (uint8_t *)malloc((size_t)w * (size_t)h * 4);
  if (!buf) return render_fail(AFM_ERR_OUT_OF_MEMORY, "out of memory for a %dx%d sheet", w, h);
  res = afm_sheet_compose(tiles, count, columns, gap, background, buf);
  if (res == AFM_OK) {
    sheet.rgba = buf;
    sheet.width = w;
    sheet.height = h;
    res = afm_png_write(path, &sheet);
  }
  free(buf);
  return res;
}
