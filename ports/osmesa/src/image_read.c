/* TGA and PNG readers. See afm/image.h. */
#define _POSIX_C_SOURCE 200809L

#include "afm/image.h"

#include <errno.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render_error.h"

void afm_image_free(afm_image *image) {
  if (!image) return;
  free(image->rgba);
  memset(image, 0, sizeof *image);
}

/* ---- TGA ----------------------------------------------------------------- */

#define TGA_HEADER 18

static unsigned le16(const uint8_t *p) { return (unsigned)p[0] | ((unsigned)p[1] << 8); }

static const char *tga_type_name(unsigned type) {
  switch (type) {
    case 0: return "no image data";
    case 1: return "colour-mapped";
    case 9: return "colour-mapped, run-length encoded";
    case 32:
    case 33: return "Huffman/delta compressed";
    default: return "unknown";
  }
}

/* One stored pixel (bytes_pp bytes, little-endian BGR(A) or grey) to RGBA. */
static void tga_pixel(const uint8_t *s, unsigned bytes_pp, int grey, uint8_t *d) {
  if (grey) {
    d[0] = d[1] = d[2] = s[0];
    d[3] = 255;
  } else if (bytes_pp == 2) {
    unsigned v = le16(s);
    unsigned r = (v >> 10) & 31u, g = (v >> 5) & 31u, b = v & 31u;
    d[0] = (uint8_t)((r << 3) | (r >> 2));
    d[1] = (uint8_t)((g << 3) | (g >> 2));
    d[2] = (uint8_t)((b << 3) | (b >> 2));
    d[3] = (v & 0x8000u) ? 255 : 0;
  } else {
    d[0] = s[2];
    d[1] = s[1];
    d[2] = s[0];
    d[3] = bytes_pp == 4 ? s[3] : 255;
  }
}

afm_result afm_tga_decode(const uint8_t *data, size_t size, const char *name, afm_image *out) {
  unsigned id_len, cmap_type, type, cmap_len, cmap_bits, width, height, depth, desc, bytes_pp;
  unsigned alpha_bits;
  int grey, rle, top_down, right_left, alpha_used = 0, any_alpha = 0;
  size_t pos, npix, i, cmap_bytes;
  uint8_t *pix, *rgba;
  render_clear_error();
  if (!name) name = "TGA";
  if (!data || !out) return render_fail(AFM_ERR_ARGUMENT, "afm_tga_decode: NULL argument");
  memset(out, 0, sizeof *out);
  if (size < TGA_HEADER)
    return render_fail(AFM_ERR_TRUNCATED, "%s: header: %zu bytes, a TGA header has 18", name, size);
  id_len = data[0];
  cmap_type = data[1];
  type = data[2];
  cmap_len = le16(data + 5);
  cmap_bits = data[7];
  width = le16(data + 12);
  height = le16(data + 14);
  depth = data[16];
  desc = data[17];
  alpha_bits = desc & 15u;
  top_down = (desc & 0x20u) != 0;
  right_left = (desc & 0x10u) != 0;
  if (type != 2 && type != 3 && type != 10 && type != 11)
    return render_fail(AFM_ERR_RANGE,
                       "%s: header: image type %u (%s) is not supported; use true-colour or "
                       "greyscale, raw or run-length encoded (types 2, 3, 10, 11)",
                       name, type, tga_type_name(type));
  if (cmap_type > 1)
    return render_fail(AFM_ERR_RANGE, "%s: header: colour map type %u is not 0 or 1", name,
                       cmap_type);
  grey = type == 3 || type == 11;
  rle = type >= 9;
  if (grey ? depth != 8 : (depth != 15 && depth != 16 && depth != 24 && depth != 32))
    return render_fail(AFM_ERR_RANGE, "%s: header: %u bits per pixel is not supported for a %s image "
                       "(use %s)", name, depth, grey ? "greyscale" : "true-colour",
                       grey ? "8" : "15, 16, 24 or 32");
  if (width == 0 || height == 0 || width > AFM_IMAGE_MAX_SIZE || height > AFM_IMAGE_MAX_SIZE)
    return render_fail(AFM_ERR_RANGE, "%s: header: size %ux%u is not in 1..%d", name, width, height,
                       AFM_IMAGE_MAX_SIZE);
  bytes_pp = (depth + 7) / 8;
  /* A colour map may be present (and is skipped) even in a true-colour file. */
  cmap_bytes = cmap_type ? (size_t)cmap_len * ((cmap_bits + 7) / 8) : 0;
  pos = TGA_HEADER + id_len + cmap_bytes;
  if (pos > size)
    return render_fail(AFM_ERR_TRUNCATED, "%s: the image ID and colour map (%zu bytes) run past the "
                       "end of the file (%zu bytes)", name, pos - TGA_HEADER, size);
  npix = (size_t)width * height;
  pix = (uint8_t *)malloc(npix * 4);
  if (!pix) return render_fail(AFM_ERR_OUT_OF_MEMORY, "%s: out of memory for %ux%u pixels", name,
                               width, height);
  /* Decode in file order into pix, then place rows. */
  if (!rle) {
    if (size - pos < npix * bytes_pp) {
      size_t row = (size - pos) / ((size_t)width * bytes_pp);
      free(pix);
      return render_fail(AFM_ERR_TRUNCATED, "%s: pixel data: the file ends in stored row %zu of %u "
                         "(%zu bytes of %zu)", name, row, height, size - pos, npix * bytes_pp);
    }
    for (i = 0; i < npix; ++i) tga_pixel(data + pos + i * bytes_pp, bytes_pp, grey, pix + i * 4);
  } else {
    i = 0;
    while (i < npix) {
      unsigned head, count, k;
      size_t packet = pos;
      if (pos >= size) {
        free(pix);
        return render_fail(AFM_ERR_TRUNCATED, "%s: run-length data: the file ends at pixel %zu of %zu "
                           "(stored row %zu)", name, i, npix, i / width);
      }
      head = data[pos++];
      count = (head & 0x7Fu) + 1u;
      if (i + count > npix) {
        free(pix);
        return render_fail(AFM_ERR_RANGE, "%s: run-length data: packet at byte %zu: %u pixels from pixel "
                           "%zu run past the image's %zu", name, packet, count, i, npix);
      }
      if (head & 0x80u) {
        if (size - pos < bytes_pp) {
          free(pix);
          return render_fail(AFM_ERR_TRUNCATED, "%s: run-length data: packet at byte %zu: the file ends "
                             "inside its pixel", name, packet);
        }
        tga_pixel(data + pos, bytes_pp, grey, pix + i * 4);
        for (k = 1; k < count; ++k) memcpy(pix + (i + k) * 4, pix + i * 4, 4);
        pos += bytes_pp;
      } else {
        if (size - pos < (size_t)count * bytes_pp) {
          free(pix);
          return render_fail(AFM_ERR_TRUNCATED, "%s: run-length data: raw packet at byte %zu: the file "
                             "ends inside its %u pixels", name, packet, count);
        }
        for (k = 0; k < count; ++k) tga_pixel(data + pos + (size_t)k * bytes_pp, bytes_pp, grey,
                                              pix + (i + k) * 4);
        pos += (size_t)count * bytes_pp;
      }
      i += count;
    }
  }
  /* Alpha: only 32-bit (and 16-bit with its attribute bit) files have it. */
  if (bytes_pp == 4 || (bytes_pp == 2 && depth == 16)) {
    for (i = 0; i < npix; ++i)
      if (pix[i * 4 + 3] != 0) {
        any_alpha = 1;
        break;
      }
    alpha_used = alpha_bits > 0 && any_alpha;
    if (!alpha_used)
      for (i = 0; i < npix; ++i) pix[i * 4 + 3] = 255;
  } else if (bytes_pp == 2) {
    for (i = 0; i < npix; ++i) pix[i * 4 + 3] = 255;
  }
  if (!top_down || right_left) {
    size_t y, x, row = (size_t)width * 4;
    rgba = (uint8_t *)malloc(npix * 4);
    if (!rgba) {
      free(pix);
      return render_fail(AFM_ERR_OUT_OF_MEMORY, "%s: out of memory for %ux%u pixels", name, width,
                         height);
    }
    for (y = 0; y < height; ++y) {
      const uint8_t *src = pix + (top_down ? y : height - 1 - y) * row;
      uint8_t *dst = rgba + y * row;
      if (!right_left) {
        memcpy(dst, src, row);
      } else {
        for (x = 0; x < width; ++x) memcpy(dst + x * 4, src + (width - 1 - x) * 4, 4);
      }
    }
    free(pix);
  } else {
    rgba = pix;
  }
  out->rgba = rgba;
  out->width = (int)width;
  out->height = (int)height;
  out->has_alpha = alpha_used;
  return AFM_OK;
}

/* ---- PNG ----------------------------------------------------------------- */

afm_result afm_png_read(const char *path, afm_image *out) {
  png_image im;
  uint8_t *rgba;
  size_t bytes;
  FILE *f;
  render_clear_error();
  if (!path || !out) return render_fail(AFM_ERR_ARGUMENT, "afm_png_read: NULL argument");
  memset(out, 0, sizeof *out);
  f = fopen(path, "rb");
  if (!f) return render_fail(AFM_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
  memset(&im, 0, sizeof im);
  im.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_stdio(&im, f)) {
    render_fail(AFM_ERR_RANGE, "%s: not a readable PNG: %s", path, im.message);
    png_image_free(&im);
    fclose(f);
    return AFM_ERR_RANGE;
  }
  if (im.width == 0 || im.height == 0 || im.width > AFM_IMAGE_MAX_SIZE ||
      im.height > AFM_IMAGE_MAX_SIZE) {
    render_fail(AFM_ERR_RANGE, "%s: IHDR: size %ux%u is not in 1..%d", path, (unsigned)im.width,
                (unsigned)im.height, AFM_IMAGE_MAX_SIZE);
    png_image_free(&im);
    fclose(f);
    return AFM_ERR_RANGE;
  }
  out->has_alpha = (im.format & PNG_FORMAT_FLAG_ALPHA) != 0;
  im.format = PNG_FORMAT_RGBA;
  bytes = (size_t)im.width * im.height * 4;
  rgba = (uint8_t *)malloc(bytes);
  if (!rgba) {
    png_image_free(&im);
    fclose(f);
    return render_fail(AFM_ERR_OUT_OF_MEMORY, "%s: out of memory for %ux%u pixels", path,
                       (unsigned)im.width, (unsigned)im.height);
  }
  if (!png_image_finish_read(&im, NULL, rgba, 0, NULL)) {
    render_fail(AFM_ERR_RANGE, "%s: damaged PNG: %s", path, im.message);
    free(rgba);
    png_image_free(&im);
    fclose(f);
    return AFM_ERR_RANGE;
  }
  fclose(f);
  out->rgba = rgba;
  out->width = (int)im.width;
  out->height = (int)im.height;
  return AFM_OK;
}

/* ---- either -------------------------------------------------------------- */

afm_result afm_image_read(const char *path, afm_image *out) {
  static const uint8_t png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  uint8_t *data = NULL;
  size_t size = 0;
  afm_result r;
  render_clear_error();
  if (!path || !out) return render_fail(AFM_ERR_ARGUMENT, "afm_image_read: NULL argument");
  memset(out, 0, sizeof *out);
  errno = 0;
  r = afm_file_read(path, NULL, &data, &size);
  if (r != AFM_OK) {
    int e = errno;
    if (r == AFM_ERR_OUT_OF_MEMORY) return render_fail(r, "%s: out of memory reading it", path);
    return render_fail(r, "%s: cannot read: %s", path, e ? strerror(e) : afm_result_string(r));
  }
  if (size >= 8 && memcmp(data, png_sig, 8) == 0) {
    afm_free(NULL, data);
    return afm_png_read(path, out);
  }
  r = afm_tga_decode(data, size, path, out);
  afm_free(NULL, data);
  return r;
}
