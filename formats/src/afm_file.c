/* Whole-file read and atomic write, for tools. Embedded readers that keep the
 * model in flash do not need this file. */
#include <stdio.h>
#include <string.h>

#include "afm_internal.h"

afm_result afm_file_read(const char *path, const afm_allocator *allocator, uint8_t **data,
                         size_t *size) {
  FILE *f;
  long n;
  uint8_t *buf;
  if (!path || !data || !size) return AFM_ERR_ARGUMENT;
  *data = NULL;
  *size = 0;
  f = fopen(path, "rb");
  if (!f) return AFM_ERR_IO;
  if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
    fclose(f);
    return AFM_ERR_IO;
  }
  buf = (uint8_t *)afm_alloc(allocator, n ? (size_t)n : 1);
  if (!buf) {
    fclose(f);
    return AFM_ERR_OUT_OF_MEMORY;
  }
  if (n && fread(buf, 1, (size_t)n, f) != (size_t)n) {
    afm_free(allocator, buf);
    fclose(f);
    return AFM_ERR_IO;
  }
  fclose(f);
  *data = buf;
  *size = (size_t)n;
  return AFM_OK;
}

afm_result afm_file_write_atomic(const char *path, const uint8_t *data, size_t size) {
  char tmp[4096];
  FILE *f;
  int ok;
  if (!path || (size && !data)) return AFM_ERR_ARGUMENT;
  if (strlen(path) + 5 >= sizeof tmp) return AFM_ERR_ARGUMENT;
  strcpy(tmp, path);
  strcat(tmp, ".tmp");
  f = fopen(tmp, "wb");
  if (!f) return AFM_ERR_IO;
  ok = size == 0 || fwrite(data, 1, size, f) == size;
  ok = (fflush(f) == 0) && ok;
  ok = (fclose(f) == 0) && ok;
  if (!ok || rename(tmp, path) != 0) {
    remove(tmp);
    return AFM_ERR_IO;
  }
  return AFM_OK;
}
