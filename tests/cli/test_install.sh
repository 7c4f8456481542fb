#!/bin/sh
# `make install` gives a usable C library: a plain C99 program finds it with
# pkg-config, reads a raw AFM with libafm_format alone, and reads a draco AFM
# when it also links libafm_draco, -ldraco and -lstdc++.
set -u
: "${AFM_BUILD:=build}"
top=$(cd "$(dirname "$0")/../.." && pwd)
tmp="$top/$AFM_BUILD/test-output/cli-install"
rm -rf "$tmp"
mkdir -p "$tmp"
cd "$top" || exit 1
# The Makefile passes its config; by hand, the default build directories tell it.
config=${AFM_CONFIG:-}
if [ -z "$config" ]; then
  case "$AFM_BUILD" in
    build) config=release ;;
    build/debug | build/sanitize) config=${AFM_BUILD#build/} ;;
    *) echo "test_install.sh: set AFM_CONFIG for the build directory $AFM_BUILD"; exit 1 ;;
  esac
fi

if ! make --no-print-directory -s install config="$config" B="$AFM_BUILD" PREFIX="$tmp/prefix" \
    >"$tmp/install.log" 2>&1; then
  echo "FAIL: make install"; cat "$tmp/install.log"; exit 1
fi
for f in bin/afm-info bin/afm-import include/afm/format.h include/afm/draco.h \
         lib/libafm_format.a lib/libafm_draco.a lib/libafm_osmesa.so lib/pkgconfig/afm-player.pc; do
  [ -e "$tmp/prefix/$f" ] || { echo "FAIL: $f not installed"; exit 1; }
done

cat >"$tmp/reader.c" <<'C'
#include <stdio.h>
#include <stdlib.h>
#include <afm/format.h>
#ifdef WITH_DRACO
#include <afm/draco.h>
#endif
int main(int argc, char **argv) {
  uint8_t *data;
  size_t size;
  afm_doc *doc;
  afm_read_options ro = {0};
  afm_diag diag = {{0}};
  afm_result r;
  if (argc != 2 || afm_file_read(argv[1], NULL, &data, &size) != AFM_OK) return 2;
#ifdef WITH_DRACO
  ro.draco = afm_draco_codec();
#endif
  ro.diag = &diag;
  r = afm_doc_read_alloc(data, size, &ro, NULL, &doc);
  free(data);
  if (r != AFM_OK) {
    printf("%s\n", afm_result_string(r));
    return 1;
  }
  printf("%lu vertices\n", (unsigned long)doc->geometry.vertex_count);
  afm_free(NULL, doc);
  return 0;
}
C
# Sanitized libraries need the sanitizer runtime in the program too.
san=""
[ "$config" = sanitize ] && san="-fsanitize=address,undefined"
export PKG_CONFIG_PATH="$tmp/prefix/lib/pkgconfig"
flags=$(pkg-config --cflags --libs afm-player) || { echo "FAIL: pkg-config afm-player"; exit 1; }
# shellcheck disable=SC2086
cc -std=c99 -Wall -Werror $san "$tmp/reader.c" -o "$tmp/reader" $flags || { echo "FAIL: compile against pkg-config"; exit 1; }
# shellcheck disable=SC2086
cc -std=c99 -Wall -Werror $san -DWITH_DRACO "$tmp/reader.c" -o "$tmp/reader-draco" \
  -L"$tmp/prefix/lib" -lafm_draco $flags -ldraco -lstdc++ -lm || { echo "FAIL: compile with Draco"; exit 1; }

# --render: the installed tool finds its renderer in the prefix's lib/.
"$tmp/prefix/bin/afm-headgen" --vertices 1000 -o "$tmp/h.obj" --fdp "$tmp/h.fdp" \
    --render "$tmp/h.png" --size 40x40 >/dev/null &&
  [ -s "$tmp/h.png" ] &&
  "$tmp/prefix/bin/afm-import" "$tmp/h.obj" "$tmp/h.fdp" -o "$tmp/h.afm" >/dev/null &&
  "$tmp/prefix/bin/afm-pack" --draco "$tmp/h.afm" "$tmp/h-draco.afm" >/dev/null ||
  { echo "FAIL: installed tools"; exit 1; }
raw=$("$tmp/reader" "$tmp/h.afm")
draco=$("$tmp/reader-draco" "$tmp/h-draco.afm")
plain_on_draco=$("$tmp/reader" "$tmp/h-draco.afm")
[ "$raw" = "$draco" ] && [ -n "$raw" ] || { echo "FAIL: raw '$raw' vs draco '$draco'"; exit 1; }
case "$plain_on_draco" in
  *"no Draco codec"*) ;;
  *) echo "FAIL: a reader without Draco said '$plain_on_draco' on a draco file"; exit 1 ;;
esac
echo "test_install.sh: all passed ($raw from both profiles)"
