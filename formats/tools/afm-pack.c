/* afm-pack: convert an AFM between the raw and draco profiles. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "afm/draco.h"
#include "afm/format.h"

static void usage(FILE *out) {
  fprintf(out,
          "usage: afm-pack --raw|--draco IN.afm OUT.afm\n"
          "\n"
          "Converts an Animatable Face Model between its two profiles. Quantised values\n"
          "are kept exactly: raw -> draco -> raw gives the same bytes.\n"
          "\n"
          "  --raw     every chunk in the raw encoding: what an embedded C99 reader with\n"
          "            no library loads directly\n"
          "  --draco   geometry and morph targets through Draco where that is at least\n"
          "            %d%% smaller: the smallest file, for distribution\n"
          "  --help    this text\n"
          "\n"
          "Chunks other than geometry and morph targets, known or not, are copied as they\n"
          "are. OUT is written completely or not at all.\n",
          AFM_DRACO_MIN_SAVING_PERCENT);
}

int main(int argc, char **argv) {
  const char *in = NULL, *out = NULL;
  int profile = -1, i;
  uint8_t *data = NULL, *packed = NULL;
  size_t size = 0, packed_size = 0;
  afm_diag diag;
  afm_result r;

  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
      usage(stdout);
      return 0;
    } else if (!strcmp(argv[i], "--raw")) {
      profile = AFM_PROFILE_RAW;
    } else if (!strcmp(argv[i], "--draco")) {
      profile = AFM_PROFILE_DRACO;
    } else if (argv[i][0] == '-' && argv[i][1]) {
      fprintf(stderr, "afm-pack: unknown option '%s' (see --help)\n", argv[i]);
      return 2;
    } else if (!in) {
      in = argv[i];
    } else if (!out) {
      out = argv[i];
    } else {
      fprintf(stderr, "afm-pack: too many arguments (see --help)\n");
      return 2;
    }
  }
  if (profile < 0 || !in || !out) {
    usage(stderr);
    return 2;
  }
  r = afm_file_read(in, NULL, &data, &size);
  if (r != AFM_OK) {
    fprintf(stderr, "afm-pack: %s: cannot read: %s\n", in,
            r == AFM_ERR_IO ? strerror(errno) : afm_result_string(r));
    return 1;
  }
  memset(&diag, 0, sizeof diag);
  r = afm_transcode(data, size, (afm_profile)profile, afm_draco_codec(), NULL, &packed,
                    &packed_size, &diag);
  free(data);
  if (r != AFM_OK) {
    if (diag.message[0])
      fprintf(stderr, "afm-pack: %s: %s (at byte %lu)\n", in, diag.message,
              (unsigned long)diag.offset);
    else
      fprintf(stderr, "afm-pack: %s: %s\n", in, afm_result_string(r));
    return 1;
  }
  r = afm_file_write_atomic(out, packed, packed_size);
  afm_free(NULL, packed);
  if (r != AFM_OK) {
    fprintf(stderr, "afm-pack: %s: cannot write: %s\n", out, strerror(errno));
    return 1;
  }
  printf("%s: %lu bytes -> %s: %lu bytes (%s, %.1f%%)\n", in, (unsigned long)size, out,
         (unsigned long)packed_size, profile == AFM_PROFILE_RAW ? "raw" : "draco",
         size ? 100.0 * (double)packed_size / (double)size : 0.0);
  return 0;
}
