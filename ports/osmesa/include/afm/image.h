/* Reading images: TGA and PNG files into RGBA8, for textures and for tests
 * that compare renders with golden pictures.
 *
 * C99 (libpng for PNG). Every image comes back as RGBA8, top row first, rows
 * packed (stride = width * 4), in memory from malloc: release it with
 * afm_image_free(). Errors return an afm_result (afm/format.h) and leave a
 * message naming the file and the field in afm_render_last_error() (see
 * afm/render.h), e.g. "front.tga: header: image type 1 (colour-mapped) is
 * not supported". On error nothing is allocated.
 *
 * TGA (Truevision, version 1 and 2): true-colour images of 15, 16, 24 or 32
 * bits per pixel and 8-bit greyscale, uncompressed (types 2, 3) or
 * run-length encoded (types 10, 11; packets may cross rows), any origin
 * (bottom-left, the usual one, or top-left; right-to-left too). A 32-bit
 * image whose descriptor declares no alpha bits, or whose alpha is zero
 * everywhere (a common writer bug), reads as opaque. Colour-mapped images
 * are refused.
 *
 * PNG: any bit depth and colour type, converted to 8-bit RGBA; 16-bit
 * channels are reduced, palette and grey expanded, no gamma conversion.
 */
#ifndef AFM_IMAGE_H
#define AFM_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#include "afm/format.h"

#ifdef __cplusplus
extern "C" {
#endif

#define AFM_IMAGE_MAX_SIZE 16384 /* largest width or height accepted */

/* An image owned by the caller after a successful read. */
typedef struct afm_image {
  uint8_t *rgba; /* width * height * 4 bytes, top row first */
  int width, height;
  int has_alpha; /* non-zero when the file stores an alpha channel in use */
} afm_image;

/* Decodes a TGA file held in memory. `name` names it in messages (may be
 * NULL: "TGA"). Errors: AFM_ERR_ARGUMENT (NULL pointers), AFM_ERR_TRUNCATED
 * (header or pixel data cut short), AFM_ERR_RANGE (unsupported type or
 * depth, zero or too large a size, a run past the image's end),
 * AFM_ERR_OUT_OF_MEMORY. */
afm_result afm_tga_decode(const uint8_t *data, size_t size, const char *name, afm_image *out);

/* Reads a PNG file. AFM_ERR_IO when it cannot be opened, AFM_ERR_RANGE when
 * it is not a valid PNG or larger than AFM_IMAGE_MAX_SIZE. */
afm_result afm_png_read(const char *path, afm_image *out);

/* Reads a TGA or PNG file, told apart by the PNG signature (anything else is
 * read as TGA, which has none). */
afm_result afm_image_read(const char *path, afm_image *out);

/* Frees the pixels and zeroes the struct; NULL and zeroed images are fine. */
void afm_image_free(afm_image *image);

#ifdef __cplusplus
}
#endif

#endif /* AFM_IMAGE_H */
