/* png_diff: compares two PNG pictures for the command-line tests, with the
 * tolerance of the golden pictures (tests/render/test_render.cpp): a pixel
 * differs when a channel is off by more than 24, and the pictures match when
 * at most 0.25 % of the pixels differ and the mean difference per channel is
 * at most 1 count. Prints the figures; exit 0 when they match, 1 when they do
 * not (or differ in size), 2 when a file cannot be read.
 *
 *   png_diff A.png B.png */
#include <afm/image.h>
#include <afm/render.h>
#include <stdio.h>
#include <stdlib.h>

#define PIXEL_TOLERANCE 24
#define MAX_DIFFERING 0.0025
#define MAX_MEAN 1.0

int main(int argc, char **argv) {
  afm_image a = {0}, b = {0};
  size_t i, n, off = 0;
  double sum = 0;
  int k, worst = 0, match;
  if (argc != 3) {
    fprintf(stderr, "usage: png_diff A.png B.png\n");
    return 2;
  }
  if (afm_png_read(argv[1], &a) != AFM_OK || afm_png_read(argv[2], &b) != AFM_OK) {
    fprintf(stderr, "png_diff: %s\n", afm_render_last_error());
    afm_image_free(&a);
    return 2;
  }
  if (a.width != b.width || a.height != b.height) {
    printf("sizes differ: %dx%d and %dx%d\n", a.width, a.height, b.width, b.height);
    afm_image_free(&a);
    afm_image_free(&b);
    return 1;
  }
  n = (size_t)a.width * (size_t)a.height;
  for (i = 0; i < n; ++i) {
    int m = 0;
    for (k = 0; k < 4; ++k) {
      int d = abs(a.rgba[i * 4 + (size_t)k] - b.rgba[i * 4 + (size_t)k]);
      sum += d;
      if (d > m) m = d;
    }
    if (m > PIXEL_TOLERANCE) ++off;
    if (m > worst) worst = m;
  }
  match = (double)off / (double)n <= MAX_DIFFERING && sum / (4.0 * (double)n) <= MAX_MEAN;
  printf("%dx%d: %.3f %% of the pixels off by more than %d (at most %.2f %%), mean difference %.4f "
         "(at most %.1f), largest %d: %s\n",
         a.width, a.height, 100.0 * (double)off / (double)n, PIXEL_TOLERANCE, 100.0 * MAX_DIFFERING,
         sum / (4.0 * (double)n), MAX_MEAN, worst, match ? "match" : "differ");
  afm_image_free(&a);
  afm_image_free(&b);
  return match ? 0 : 1;
}
