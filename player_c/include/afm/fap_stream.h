/* ASCII MPEG-4 FAP streams (.fap): incremental and whole-buffer readers.
 *
 * C99, no dependencies, no globals, no allocation, no floating point: decimal
 * values are rounded to integers with integer arithmetic, so every platform
 * reads every file to the same bits. The format and the real-world variants
 * accepted are specified in formats/fap.md:
 *   - versions 2.0, 2.1 and 2.2;
 *   - LF, CRLF or CR line ends; spaces or tabs; '#' comments anywhere;
 *   - integer or decimal values, with an optional exponent ("-4.61945",
 *     "10.", ".5", "1e+06"), rounded half away from zero;
 *   - 68- or 69-entry masks (the 69th FAP is not standard and is skipped);
 *   - FAP 1 with 4 values (or the single-value form one writer uses), FAP 2
 *     with 6 values;
 *   - frame numbers from any start, increasing, gaps allowed.
 *
 * Values outside a FAP's range (afm_fap_value_range) are clamped and counted
 * in afm_fap_stats. Errors name the line in afm_diag.line (and in the message:
 * "line 14: mask has 67 entries, expected 68 or 69"); afm_diag.offset is the
 * byte offset of that line's start (the stream's length for the end-of-stream
 * checks of afm_fap_reader_finish):
 *   AFM_ERR_SYNTAX     the line does not parse, or breaks a rule (frame numbers
 *                      not increasing, more frames than the header states);
 *   AFM_ERR_LIMIT      a line longer than AFM_FAP_MAX_LINE;
 *   AFM_ERR_TRUNCATED  the input ends before the header, between a mask and its
 *                      value line, or before the header's frame count;
 *   AFM_ERR_STATE      feeding a finished reader;
 *   AFM_ERR_ARGUMENT   NULL pointers, unknown option flags.
 */
#ifndef AFM_FAP_STREAM_H
#define AFM_FAP_STREAM_H

#include <stddef.h>
#include <stdint.h>

#include "afm/format.h"
#include "afm/mpeg4.h"

#ifdef __cplusplus
extern "C" {
#endif

#define AFM_FAP_MAX_LINE 4096 /* bytes per line, line end excluded, comment included */

/* Value ranges (formats/fap.md, "Value ranges"). */
#define AFM_FAP_DISTANCE_LIMIT 16384   /* |value| of FAPs in IRISD, ES, ENS, MNS, MW units */
#define AFM_FAP_ANGLE_LIMIT 314159     /* |value| of FAPs in AU: pi rad */
#define AFM_FAP_INTENSITY_MAX 63       /* viseme_blend, expression_intensity1/2 */

typedef struct afm_fap_header {
  uint8_t version_major, version_minor; /* 2.1 -> 2, 1 */
  char name[256];                       /* the name field as written (may hold spaces; empty
                                           when absent), truncated to 255 bytes */
  uint32_t fps_num, fps_den;            /* frames per second as a reduced ratio: "25" -> 25/1,
                                           "29.97" -> 2997/100, "12.50" -> 25/2 */
  uint32_t frame_count;                 /* as the header states */
} afm_fap_header;

/* FAP 1 payload. Visemes 0..14 (afm_viseme_name), blend 0..63, def 0..1. */
typedef struct afm_viseme_value {
  uint8_t select1, select2, blend, def;
} afm_viseme_value;

/* FAP 2 payload. Expressions 0..6 (afm_expression_name), intensities 0..63,
 * init_face and def 0..1. */
typedef struct afm_expression_value {
  uint8_t select1, intensity1, select2, intensity2, init_face, def;
} afm_expression_value;

/* One frame as the stream sends it. */
typedef struct afm_fap_frame {
  uint32_t number;                  /* frame number as written */
  uint32_t line;                    /* line of the frame's value line */
  uint8_t mask[AFM_FAP_COUNT + 1];  /* mask[f] = 1 when FAP f (1..68) is sent; [0] unused */
  int32_t value[AFM_FAP_COUNT + 1]; /* FAP f (3..68) in FAP units (AU for rotations),
                                       rounded half away from zero and clamped; 0 when
                                       not sent; [0..2] unused */
  afm_viseme_value viseme;          /* valid when mask[1]; a single-value payload v
                                       reads as v 0 63 0 (select1 at full blend) */
  afm_expression_value expression;  /* valid when mask[2] */
} afm_fap_frame;

typedef struct afm_fap_stats {
  uint32_t frames;          /* frames delivered */
  uint32_t clamped;         /* values clamped to their FAP's (or field's) range */
  uint32_t rounded;         /* values that were not integers (before clamping) */
  uint32_t comment_lines;   /* lines holding only a comment */
  uint32_t masks_69;        /* 69-entry masks (the 69th entry ignored) */
  uint32_t single_visemes;  /* FAP 1 payloads of one value */
  uint32_t skipped_values;  /* values of the 69th FAP, read and dropped */
} afm_fap_stats;

#define AFM_FAP_V20_DIVIDE_BY_20 0x1u /* option: divide the FAP 3..68 values of version 2.0
                                         streams by 20 (before rounding), as one player
                                         does (formats/fap.md) */

/* Zeroed: the defaults. */
typedef struct afm_fap_reader_options {
  uint32_t flags; /* AFM_FAP_*; other bits are refused (AFM_ERR_ARGUMENT) */
} afm_fap_reader_options;

/* Reader state. Caller-owned (about 4.5 KB: the line buffer); the fields are
 * private. */
typedef struct afm_fap_reader {
  afm_fap_reader_options options;
  afm_diag *diag;
  afm_fap_header header;
  afm_fap_stats stats;
  int state;                /* private: header, mask or values next; finished; failed */
  afm_result error;         /* private: sticky error */
  uint32_t line;            /* private: lines started (the current line's number) */
  uint32_t line_length;     /* private: bytes of a partial line in `buffer` */
  uint64_t position;        /* private: bytes taken so far */
  uint64_t line_offset;     /* private: offset of the current line's first byte */
  int last_was_cr;          /* private: the previous byte ended a line with CR */
  int have_first_number;    /* private */
  uint32_t last_number;     /* private */
  uint8_t mask[AFM_FAP_COUNT + 2]; /* private: the pending mask (69 entries) */
  uint8_t mask_entries;     /* private: 68 or 69 */
  uint8_t low_count;        /* private: FAPs 3..68 in the pending mask */
  uint8_t low[AFM_FAP_COUNT];      /* private: their numbers, ascending */
  uint32_t mask_line;       /* private */
  char buffer[AFM_FAP_MAX_LINE + 1]; /* private: the line being assembled */
} afm_fap_reader;

/* Prepares a reader. `options` and `diag` may be NULL; diag must outlive the
 * reader. */
void afm_fap_reader_init(afm_fap_reader *reader, const afm_fap_reader_options *options,
                         afm_diag *diag);

/* Takes bytes up to the end of the line that completes a frame, or all of
 * them. *consumed gets the bytes taken; *has_frame is 1 when `frame` holds a
 * new frame, and then the caller calls again with the rest of the data.
 * Data may be split anywhere, even between CR and LF: the frames, stats and
 * errors are the same as for one buffer. A partial last line is kept until
 * more data or afm_fap_reader_finish. On error *consumed covers the failing
 * line (or part of it) and `frame` is unspecified. Errors are sticky: after
 * one, every call returns it. */
afm_result afm_fap_reader_feed(afm_fap_reader *reader, const uint8_t *data, size_t size,
                               size_t *consumed, afm_fap_frame *frame, int *has_frame);

/* Signals the end of input. A last line without a line end is read first; if
 * it completes a frame, the call returns AFM_OK with *has_frame = 1 and the
 * caller calls again. The call with *has_frame = 0 checks the end: it fails
 * with AFM_ERR_TRUNCATED when there was no header, when a mask has no value
 * line, or when fewer frames arrived than the header states (the frames
 * already delivered stay valid). Once finished, further calls return the
 * same result and feeding returns AFM_ERR_STATE. */
afm_result afm_fap_reader_finish(afm_fap_reader *reader, afm_fap_frame *frame, int *has_frame);

/* The header, or NULL before its line has been read. */
const afm_fap_header *afm_fap_reader_header(const afm_fap_reader *reader);
const afm_fap_stats *afm_fap_reader_stats(const afm_fap_reader *reader);

/* Whole buffer: parses `data` into frames[0..max_frames). With frames NULL it
 * only counts (*frame_count), so a caller sizes the array first. `header`,
 * `stats` and `diag` may be NULL.
 *   - On success *frame_count is the number of frames.
 *   - With more than max_frames frames it reads on (counting) and, if the rest
 *     parses, fails with AFM_ERR_BUFFER_TOO_SMALL with *frame_count the number
 *     needed; frames[0..max_frames) are filled.
 *   - On other errors *frame_count frames were read, and frames[0..*frame_count)
 *     (as far as they fit) are valid.
 * `header` is filled once the header line has been read; `stats` always. */
afm_result afm_fap_parse(const uint8_t *data, size_t size, const afm_fap_reader_options *options,
                         afm_fap_frame *frames, uint32_t max_frames, uint32_t *frame_count,
                         afm_fap_header *header, afm_fap_stats *stats, afm_diag *diag);

/* The range a FAP's values are clamped to, in FAP units: FAP 3..68 (see
 * formats/fap.md): +-AFM_FAP_DISTANCE_LIMIT for distance FAPs,
 * +-AFM_FAP_ANGLE_LIMIT for angle (AU) FAPs, from 0 for the unidirectional
 * ones (3, 14, 41, 42, 47). Returns 1, or 0 for other numbers (min and max
 * untouched). min or max may be NULL. */
int afm_fap_value_range(int fap, int32_t *min, int32_t *max);

#ifdef __cplusplus
}
#endif

#endif /* AFM_FAP_STREAM_H */
