/* ASCII FAP stream reader (formats/fap.md). Integer arithmetic only. */
#include "afm/fap_stream.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

enum { ST_HEADER = 0, ST_MASK, ST_VALUES, ST_FINISHED, ST_FAILED };

/* Values beyond this saturate while being parsed: far outside every range, and
 * x * 10 cannot overflow 64 bits. */
#define SATURATE ((uint64_t)1 << 40)
/* Significant digits kept of a decimal: 10^17 * 20 still fits 64 bits. */
#define MAX_DIGITS 17

static const uint64_t kPow10[MAX_DIGITS + 1] = {
    1ull,
    10ull,
    100ull,
    1000ull,
    10000ull,
    100000ull,
    1000000ull,
    10000000ull,
    100000000ull,
    1000000000ull,
    10000000000ull,
    100000000000ull,
    1000000000000ull,
    10000000000000ull,
    100000000000000ull,
    1000000000000000ull,
    10000000000000000ull,
    100000000000000000ull,
};

static int is_space(char c) { return c == ' ' || c == '\t'; }
static int is_digit(char c) { return c >= '0' && c <= '9'; }

/* ---- diagnostics ----------------------------------------------------------- */

static afm_result fail(afm_fap_reader *r, afm_result result, uint32_t line, const char *format,
                       ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static afm_result fail(afm_fap_reader *r, afm_result result, uint32_t line, const char *format,
                       ...) {
  r->state = ST_FAILED;
  r->error = result;
  if (r->diag) {
    va_list args;
    int n = snprintf(r->diag->message, sizeof r->diag->message, "line %lu: ",
                     (unsigned long)line);
    if (n < 0 || (size_t)n >= sizeof r->diag->message) n = 0;
    va_start(args, format);
    vsnprintf(r->diag->message + n, sizeof r->diag->message - (size_t)n, format, args);
    va_end(args);
    r->diag->line = line;
    r->diag->offset = r->line_offset;
    r->diag->chunk = 0;
  }
  return result;
}

/* A token for a message, into q: at most 24 bytes, unprintable bytes as '?'. */
#define QUOTE_SIZE 32
static const char *quote(char *q, const char *s, size_t n) {
  size_t i, m = n > 24 ? 24 : n;
  for (i = 0; i < m; ++i) {
    unsigned char c = (unsigned char)s[i];
    q[i] = (c >= 0x20 && c < 0x7f) ? (char)c : '?';
  }
  if (m < n) {
    q[m++] = '.';
    q[m++] = '.';
    q[m++] = '.';
  }
  q[m] = '\0';
  return q;
}

/* ---- tokens and numbers ------------------------------------------------------ */

/* Next whitespace-separated token of [*p, end): returns 0 at the end. */
static int next_token(const char **p, const char *end, const char **tok, size_t *len) {
  const char *s = *p;
  while (s < end && is_space(*s)) ++s;
  if (s == end) {
    *p = s;
    return 0;
  }
  *tok = s;
  while (s < end && !is_space(*s)) ++s;
  *len = (size_t)(s - *tok);
  *p = s;
  return 1;
}

static uint32_t count_tokens(const char *p, const char *end) {
  const char *tok = NULL;
  size_t len = 0;
  uint32_t n = 0;
  while (next_token(&p, end, &tok, &len)) ++n;
  return n;
}

/* Unsigned decimal integer, digits only, below 2^32. */
static int parse_u32(const char *s, size_t n, uint32_t *out) {
  uint64_t v = 0;
  size_t i;
  if (n == 0) return 0;
  for (i = 0; i < n; ++i) {
    if (!is_digit(s[i])) return 0;
    v = v * 10 + (uint64_t)(s[i] - '0');
    if (v > 0xFFFFFFFFu) return 0;
  }
  *out = (uint32_t)v;
  return 1;
}

/* A decimal [+-] digits [. digits] [(e|E) [+-] digits] (at least one mantissa
 * digit), divided by `divisor` and rounded half away from zero, exactly:
 * the mantissa's first 17 significant digits are an integer m and the value
 * m * 10^e; digits past those only matter when the integer part is beyond
 * 10^16 (saturated anyway) or to tell that the value was not an integer.
 * *fraction is 1 when the exact quotient is not an integer. Returns 0 when
 * the token is not such a number. */
static int parse_value(const char *s, size_t n, uint32_t divisor, int64_t *out, int *fraction) {
  size_t i = 0;
  int negative = 0, digits = 0, significant = 0, sticky = 0;
  uint64_t m = 0, q, rem, den;
  long exp10 = 0;

  if (i < n && (s[i] == '+' || s[i] == '-')) negative = s[i++] == '-';
  for (; i < n && is_digit(s[i]); ++i) {
    unsigned d = (unsigned)(s[i] - '0');
    ++digits;
    if (significant < MAX_DIGITS) {
      m = m * 10 + d;
      if (m) ++significant;
    } else {
      ++exp10;
      sticky |= d != 0;
    }
  }
  if (i < n && s[i] == '.') {
    for (++i; i < n && is_digit(s[i]); ++i) {
      unsigned d = (unsigned)(s[i] - '0');
      ++digits;
      if (significant < MAX_DIGITS) {
        m = m * 10 + d;
        --exp10;
        if (m) ++significant;
      } else {
        sticky |= d != 0;
      }
    }
  }
  if (digits == 0) return 0;
  if (i < n && (s[i] == 'e' || s[i] == 'E')) {
    int eneg = 0, edigits = 0;
    long e = 0;
    ++i;
    if (i < n && (s[i] == '+' || s[i] == '-')) eneg = s[i++] == '-';
    for (; i < n && is_digit(s[i]); ++i) {
      ++edigits;
      if (e < 100000) e = e * 10 + (s[i] - '0');
    }
    if (edigits == 0) return 0;
    exp10 += eneg ? -e : e;
  }
  if (i != n) return 0;

  if (m == 0) {
    *out = 0;
    *fraction = 0;
    return 1;
  }
  if (exp10 >= 0) {
    uint64_t v = m;
    long k;
    for (k = 0; k < exp10 && v < SATURATE; ++k) v *= 10;
    if (v >= SATURATE) {
      *out = negative ? -(int64_t)SATURATE : (int64_t)SATURATE;
      *fraction = 0;
      return 1;
    }
    den = divisor;
    q = v / den;
    rem = v % den;
  } else if (-exp10 > MAX_DIGITS) {
    /* m < 10^17, so |value| < 0.1 (and < 0.1 / divisor): rounds to 0. */
    *out = 0;
    *fraction = 1;
    return 1;
  } else {
    den = kPow10[-exp10] * divisor;
    q = m / den;
    rem = m % den;
  }
  /* Half away from zero: up when rem / den >= 1/2; dropped digits only add. */
  if (rem >= den - rem) ++q;
  *fraction = rem != 0 || sticky;
  *out = negative ? -(int64_t)q : (int64_t)q;
  return 1;
}

static int32_t clamp(int64_t v, int32_t lo, int32_t hi, uint32_t *clamped) {
  if (v < lo) {
    ++*clamped;
    return lo;
  }
  if (v > hi) {
    ++*clamped;
    return hi;
  }
  return (int32_t)v;
}

/* ---- value ranges -------------------------------------------------------- */

int afm_fap_value_range(int fap, int32_t *min, int32_t *max) {
  const afm_fap_info *info;
  int32_t limit;
  if (fap < 3 || fap > AFM_FAP_COUNT) return 0;
  info = afm_fap(fap);
  if (!info) return 0;
  limit = info->unit == AFM_FAPU_AU ? AFM_FAP_ANGLE_LIMIT : AFM_FAP_DISTANCE_LIMIT;
  if (min) *min = info->bidirectional ? -limit : 0;
  if (max) *max = limit;
  return 1;
}

/* ---- lines --------------------------------------------------------------- */

static afm_result parse_header(afm_fap_reader *r, uint32_t ln, const char *p, const char *end) {
  const char *tok[3] = {NULL, NULL, NULL}, *name_begin, *name_end, *s;
  size_t len[3] = {0, 0, 0};
  uint32_t fields = count_tokens(p, end);
  uint64_t num = 0, den = 1, a, b;
  size_t i;
  int seen_dot = 0, digits = 0;
  char q[QUOTE_SIZE];

  if (fields < 3)
    return fail(r, AFM_ERR_SYNTAX, ln,
                "header has %lu fields, expected <version> <name> <fps> <frame count>",
                (unsigned long)fields);
  /* Version: the first token; fps and frame count: the last two; the name is
   * what lies between, so it may hold spaces. */
  s = p;
  next_token(&s, end, &tok[0], &len[0]);
  name_begin = s;
  s = end;
  while (is_space(s[-1])) --s;
  tok[2] = s;
  while (!is_space(tok[2][-1])) --tok[2];
  len[2] = (size_t)(s - tok[2]);
  s = tok[2];
  while (is_space(s[-1])) --s;
  tok[1] = s;
  while (!is_space(tok[1][-1])) --tok[1];
  len[1] = (size_t)(s - tok[1]);
  name_end = tok[1];
  while (name_begin < name_end && is_space(*name_begin)) ++name_begin;
  while (name_end > name_begin && is_space(name_end[-1])) --name_end;

  if (len[0] != 3 || tok[0][0] != '2' || tok[0][1] != '.' || tok[0][2] < '0' ||
      tok[0][2] > '2')
    return fail(r, AFM_ERR_SYNTAX, ln, "version '%s' not supported (2.0, 2.1 or 2.2)",
                quote(q, tok[0], len[0]));

  for (i = 0; i < len[1]; ++i) {
    char c = tok[1][i];
    if (c == '.' && !seen_dot) {
      seen_dot = 1;
    } else if (is_digit(c)) {
      ++digits;
      num = num * 10 + (uint64_t)(c - '0');
      if (seen_dot) den *= 10;
      if (num > 0xFFFFFFFFu || den > 1000000000u) break;
    } else {
      break;
    }
  }
  if (i != len[1] || digits == 0 || num == 0)
    return fail(r, AFM_ERR_SYNTAX, ln,
                "frame rate '%s' is not a positive decimal (at most 4294967295 and 9 decimals)",
                quote(q, tok[1], len[1]));
  /* Reduce: "29.97" -> 2997/100, "25.0" -> 25/1. */
  a = num;
  b = den;
  while (b) {
    uint64_t t = a % b;
    a = b;
    b = t;
  }
  if (!parse_u32(tok[2], len[2], &r->header.frame_count))
    return fail(r, AFM_ERR_SYNTAX, ln, "frame count '%s' is not an integer below 2^32",
                quote(q, tok[2], len[2]));

  r->header.version_major = 2;
  r->header.version_minor = (uint8_t)(tok[0][2] - '0');
  r->header.fps_num = (uint32_t)(num / a);
  r->header.fps_den = (uint32_t)(den / a);
  i = (size_t)(name_end - name_begin);
  if (i > sizeof r->header.name - 1) i = sizeof r->header.name - 1;
  memcpy(r->header.name, name_begin, i);
  r->header.name[i] = '\0';
  r->state = ST_MASK;
  return AFM_OK;
}

static afm_result parse_mask(afm_fap_reader *r, uint32_t ln, const char *p, const char *end) {
  uint32_t n = 0;
  const char *tok = NULL;
  size_t len = 0;
  int f;
  char q[QUOTE_SIZE];

  if (r->stats.frames >= r->header.frame_count)
    return fail(r, AFM_ERR_SYNTAX, ln,
                "more frames than the %lu the header states",
                (unsigned long)r->header.frame_count);
  while (next_token(&p, end, &tok, &len)) {
    if (n == AFM_FAP_COUNT + 1) {
      n += 1 + count_tokens(p, end);
      return fail(r, AFM_ERR_SYNTAX, ln, "mask has %lu entries, expected 68 or 69",
                  (unsigned long)n);
    }
    if (len != 1 || (tok[0] != '0' && tok[0] != '1'))
      return fail(r, AFM_ERR_SYNTAX, ln, "mask entry %lu is '%s', expected 0 or 1",
                  (unsigned long)(n + 1), quote(q, tok, len));
    r->mask[++n] = (uint8_t)(tok[0] - '0');
  }
  if (n < AFM_FAP_COUNT)
    return fail(r, AFM_ERR_SYNTAX, ln, "mask has %lu entries, expected 68 or 69",
                (unsigned long)n);
  if (n == AFM_FAP_COUNT) r->mask[AFM_FAP_COUNT + 1] = 0;
  r->mask_entries = (uint8_t)n;
  r->low_count = 0;
  for (f = 3; f <= AFM_FAP_COUNT; ++f)
    if (r->mask[f]) r->low[r->low_count++] = (uint8_t)f;
  r->mask_line = ln;
  r->state = ST_VALUES;
  return AFM_OK;
}

/* Counters of one value line, added to the stats when the frame is taken. */
typedef struct line_counts {
  uint32_t clamped, rounded;
} line_counts;

/* Reads the next value of the line; the message names its position. */
static afm_result take_value(afm_fap_reader *r, uint32_t ln, const char **p, const char *end,
                             uint32_t index, uint32_t expected, uint32_t divisor, int64_t *v,
                             line_counts *c) {
  const char *tok = NULL;
  size_t len = 0;
  int fraction;
  char q[QUOTE_SIZE];
  if (!next_token(p, end, &tok, &len))
    return fail(r, AFM_ERR_SYNTAX, ln, "%lu values, expected %lu", (unsigned long)index,
                (unsigned long)expected);
  if (!parse_value(tok, len, divisor, v, &fraction))
    return fail(r, AFM_ERR_SYNTAX, ln, "value %lu ('%s') is not a number",
                (unsigned long)(index + 1), quote(q, tok, len));
  c->rounded += (uint32_t)fraction;
  return AFM_OK;
}

#define TAKE(field_index, divisor)                                                        \
  do {                                                                                    \
    afm_result res_ =                                                                     \
        take_value(r, ln, &p, end, (field_index), expected, (divisor), &v, &counts);      \
    if (res_ != AFM_OK) return res_;                                                      \
  } while (0)

static afm_result parse_values(afm_fap_reader *r, uint32_t ln, const char *p, const char *end,
                               afm_fap_frame *frame, int *has_frame) {
  const char *tok = NULL;
  size_t len = 0;
  uint32_t number, expected, base, index = 0, visemes = 0, i;
  uint32_t divisor = 1;
  line_counts counts = {0, 0};
  int64_t v;
  char q[QUOTE_SIZE];
  int has_extra = r->mask_entries > AFM_FAP_COUNT && r->mask[AFM_FAP_COUNT + 1];

  if (r->header.version_minor == 0 && (r->options.flags & AFM_FAP_V20_DIVIDE_BY_20)) divisor = 20;

  next_token(&p, end, &tok, &len); /* the line is not blank */
  if (!parse_u32(tok, len, &number))
    return fail(r, AFM_ERR_SYNTAX, ln, "frame number '%s' is not an integer 0..4294967295",
                quote(q, tok, len));
  if (r->have_first_number && number <= r->last_number)
    return fail(r, AFM_ERR_SYNTAX, ln, "frame number %lu after %lu: frame numbers must increase",
                (unsigned long)number, (unsigned long)r->last_number);

  base = r->low_count + (r->mask[2] ? 6u : 0u) + (has_extra ? 1u : 0u);
  if (r->mask[1]) {
    /* FAP 1 is 4 values, or 1 from one writer: the count tells which. */
    uint32_t n = count_tokens(p, end);
    if (n == base + 4) {
      visemes = 4;
    } else if (n == base + 1) {
      visemes = 1;
    } else {
      return fail(r, AFM_ERR_SYNTAX, ln,
                  "%lu values, expected %lu (FAP 1 as 4 values) or %lu (FAP 1 as 1 value)",
                  (unsigned long)n, (unsigned long)(base + 4), (unsigned long)(base + 1));
    }
  }
  expected = base + visemes;

  memset(frame, 0, sizeof *frame);
  frame->number = number;
  frame->line = ln;
  memcpy(frame->mask + 1, r->mask + 1, AFM_FAP_COUNT);

  if (visemes) {
    afm_viseme_value *vi = &frame->viseme;
    TAKE(index++, 1);
    vi->select1 = (uint8_t)clamp(v, 0, AFM_VISEME_COUNT - 1, &counts.clamped);
    if (visemes == 4) {
      TAKE(index++, 1);
      vi->select2 = (uint8_t)clamp(v, 0, AFM_VISEME_COUNT - 1, &counts.clamped);
      TAKE(index++, 1);
      vi->blend = (uint8_t)clamp(v, 0, AFM_FAP_INTENSITY_MAX, &counts.clamped);
      TAKE(index++, 1);
      vi->def = (uint8_t)clamp(v, 0, 1, &counts.clamped);
    } else {
      vi->select2 = 0;
      vi->blend = AFM_FAP_INTENSITY_MAX;
      vi->def = 0;
    }
  }
  if (r->mask[2]) {
    afm_expression_value *ex = &frame->expression;
    TAKE(index++, 1);
    ex->select1 = (uint8_t)clamp(v, 0, AFM_EXPRESSION_COUNT - 1, &counts.clamped);
    TAKE(index++, 1);
    ex->intensity1 = (uint8_t)clamp(v, 0, AFM_FAP_INTENSITY_MAX, &counts.clamped);
    TAKE(index++, 1);
    ex->select2 = (uint8_t)clamp(v, 0, AFM_EXPRESSION_COUNT - 1, &counts.clamped);
    TAKE(index++, 1);
    ex->intensity2 = (uint8_t)clamp(v, 0, AFM_FAP_INTENSITY_MAX, &counts.clamped);
    TAKE(index++, 1);
    ex->init_face = (uint8_t)clamp(v, 0, 1, &counts.clamped);
    TAKE(index++, 1);
    ex->def = (uint8_t)clamp(v, 0, 1, &counts.clamped);
  }
  for (i = 0; i < r->low_count; ++i) {
    int f = r->low[i];
    int32_t lo = 0, hi = 0;
    TAKE(index++, divisor);
    afm_fap_value_range(f, &lo, &hi);
    frame->value[f] = clamp(v, lo, hi, &counts.clamped);
  }
  if (has_extra) {
    /* The 69th FAP: not standard; read (it must be a number) and dropped. */
    line_counts ignored = {0, 0};
    afm_result res = take_value(r, ln, &p, end, index++, expected, 1, &v, &ignored);
    if (res != AFM_OK) return res;
  }
  if (next_token(&p, end, &tok, &len))
    return fail(r, AFM_ERR_SYNTAX, ln, "%lu values, expected %lu",
                (unsigned long)(index + 1 + count_tokens(p, end)), (unsigned long)expected);

  r->have_first_number = 1;
  r->last_number = number;
  r->stats.frames++;
  r->stats.clamped += counts.clamped;
  r->stats.rounded += counts.rounded;
  if (r->mask_entries > AFM_FAP_COUNT) r->stats.masks_69++;
  if (has_extra) r->stats.skipped_values++;
  if (visemes == 1) r->stats.single_visemes++;
  r->state = ST_MASK;
  *has_frame = 1;
  return AFM_OK;
}

#undef TAKE

/* One complete line, line end excluded. */
static afm_result process_line(afm_fap_reader *r, const char *line, size_t length,
                               afm_fap_frame *frame, int *has_frame) {
  const char *p = line, *end = line + length, *hash;
  uint32_t ln = r->line;

  if (length > AFM_FAP_MAX_LINE)
    return fail(r, AFM_ERR_LIMIT, ln, "line longer than %d bytes", AFM_FAP_MAX_LINE);
  if (ln == 1 && length >= 3 && (unsigned char)p[0] == 0xEF && (unsigned char)p[1] == 0xBB &&
      (unsigned char)p[2] == 0xBF)
    p += 3; /* UTF-8 byte order mark */
  hash = memchr(p, '#', (size_t)(end - p));
  if (hash) end = hash;
  while (p < end && is_space(*p)) ++p;
  while (end > p && is_space(end[-1])) --end;
  if (p == end) {
    if (hash) r->stats.comment_lines++;
    return AFM_OK;
  }
  switch (r->state) {
    case ST_HEADER: return parse_header(r, ln, p, end);
    case ST_MASK: return parse_mask(r, ln, p, end);
    default: return parse_values(r, ln, p, end, frame, has_frame);
  }
}

/* ---- the reader -------------------------------------------------------------- */

void afm_fap_reader_init(afm_fap_reader *reader, const afm_fap_reader_options *options,
                         afm_diag *diag) {
  if (!reader) return;
  memset(reader, 0, offsetof(afm_fap_reader, buffer));
  reader->buffer[0] = '\0';
  if (options) reader->options = *options;
  reader->diag = diag;
  reader->state = ST_HEADER;
  reader->error = AFM_OK;
  reader->line = 1;
  if (reader->options.flags & ~AFM_FAP_V20_DIVIDE_BY_20) {
    reader->state = ST_FAILED;
    reader->error = AFM_ERR_ARGUMENT;
    if (diag) {
      snprintf(diag->message, sizeof diag->message, "unknown FAP reader option flags 0x%lx",
               (unsigned long)reader->options.flags);
      diag->line = 0;
    }
  }
}

/* Starts the next line: numbers it, notes its offset. */
static void next_line(afm_fap_reader *r) {
  if (r->line != 0xFFFFFFFFu) ++r->line;
  r->line_length = 0;
  r->line_offset = r->position;
}

afm_result afm_fap_reader_feed(afm_fap_reader *reader, const uint8_t *data, size_t size,
                               size_t *consumed, afm_fap_frame *frame, int *has_frame) {
  afm_fap_reader *r = reader;
  size_t i = 0;
  if (consumed) *consumed = 0;
  if (has_frame) *has_frame = 0;
  if (!r || !consumed || !has_frame || !frame || (!data && size)) return AFM_ERR_ARGUMENT;
  if (r->state == ST_FAILED) return r->error;
  if (r->state == ST_FINISHED) return AFM_ERR_STATE;

  while (i < size) {
    const uint8_t *p = data + i, *lf, *cr;
    size_t n = size - i, k;
    const char *line;
    size_t length;
    afm_result res;

    if (r->last_was_cr) {
      /* LF after CR: the same line end, even across calls. */
      r->last_was_cr = 0;
      if (*p == '\n') {
        ++i;
        ++r->position;
        r->line_offset = r->position;
        continue;
      }
    }
    lf = memchr(p, '\n', n);
    k = lf ? (size_t)(lf - p) : n;
    cr = memchr(p, '\r', k);
    if (cr) k = (size_t)(cr - p);

    if (k == n) {
      /* No line end yet: keep the bytes (or fail now if the line is too long). */
      if (n > AFM_FAP_MAX_LINE - r->line_length) {
        *consumed = size;
        r->position += size - i;
        return fail(r, AFM_ERR_LIMIT, r->line, "line longer than %d bytes", AFM_FAP_MAX_LINE);
      }
      memcpy(r->buffer + r->line_length, p, n);
      r->line_length += (uint32_t)n;
      r->position += n;
      i = size;
      break;
    }
    if (r->line_length == 0) {
      line = (const char *)p; /* the whole line is here: read it in place */
      length = k;
    } else {
      if (k > AFM_FAP_MAX_LINE - r->line_length) {
        *consumed = i + k + 1;
        return fail(r, AFM_ERR_LIMIT, r->line, "line longer than %d bytes", AFM_FAP_MAX_LINE);
      }
      memcpy(r->buffer + r->line_length, p, k);
      line = r->buffer;
      length = r->line_length + k;
    }
    r->last_was_cr = p[k] == '\r';
    i += k + 1;
    r->position += k + 1;
    res = process_line(r, line, length, frame, has_frame);
    next_line(r);
    if (res != AFM_OK || *has_frame) {
      *consumed = i;
      return res;
    }
  }
  *consumed = i;
  return AFM_OK;
}

afm_result afm_fap_reader_finish(afm_fap_reader *reader, afm_fap_frame *frame, int *has_frame) {
  afm_fap_reader *r = reader;
  uint32_t last;
  if (has_frame) *has_frame = 0;
  if (!r || !frame || !has_frame) return AFM_ERR_ARGUMENT;
  if (r->state == ST_FAILED) return r->error;
  if (r->state == ST_FINISHED) return AFM_OK;

  if (r->line_length > 0) {
    afm_result res = process_line(r, r->buffer, r->line_length, frame, has_frame);
    next_line(r);
    if (res == AFM_ERR_SYNTAX) {
      /* A last line without a line end that does not parse cannot be told
       * from a cut one ("5 10 " of "5 10 20", "-" of "-3"): the stream ends
       * inside it. The message keeps the detail. */
      r->error = AFM_ERR_TRUNCATED;
      if (r->diag) {
        size_t n = strlen(r->diag->message);
        snprintf(r->diag->message + n, sizeof r->diag->message - n,
                 " (the last line has no line end: the stream may be cut)");
      }
      return AFM_ERR_TRUNCATED;
    }
    if (res != AFM_OK || *has_frame) return res;
  }
  /* r->line is one past the last line: name the last one (the offset is the
   * stream's length). */
  last = r->line > 1 ? r->line - 1 : 1;
  r->line_offset = r->position;
  if (r->state == ST_HEADER)
    return fail(r, AFM_ERR_TRUNCATED, last, "the stream ends before its header line");
  if (r->state == ST_VALUES)
    return fail(r, AFM_ERR_TRUNCATED, r->mask_line,
                "the stream ends after this mask, without its value line");
  if (r->stats.frames < r->header.frame_count)
    return fail(r, AFM_ERR_TRUNCATED, last,
                "the stream ends after %lu of the %lu frames the header states",
                (unsigned long)r->stats.frames, (unsigned long)r->header.frame_count);
  r->state = ST_FINISHED;
  return AFM_OK;
}

const afm_fap_header *afm_fap_reader_header(const afm_fap_reader *reader) {
  if (!reader) return NULL;
  if (reader->header.version_major == 0) return NULL;
  return &reader->header;
}

const afm_fap_stats *afm_fap_reader_stats(const afm_fap_reader *reader) {
  return reader ? &reader->stats : NULL;
}

/* ---- whole buffer -------------------------------------------------------------- */

afm_result afm_fap_parse(const uint8_t *data, size_t size, const afm_fap_reader_options *options,
                         afm_fap_frame *frames, uint32_t max_frames, uint32_t *frame_count,
                         afm_fap_header *header, afm_fap_stats *stats, afm_diag *diag) {
  afm_fap_reader reader;
  afm_fap_frame scratch;
  uint32_t count = 0;
  size_t at = 0;
  afm_result res = AFM_OK;
  int too_small = 0;

  if (frame_count) *frame_count = 0;
  if (!frame_count || (!data && size)) return AFM_ERR_ARGUMENT;
  afm_fap_reader_init(&reader, options, diag);
  for (;;) {
    afm_fap_frame *slot = (frames && count < max_frames) ? &frames[count] : &scratch;
    size_t used = 0;
    int has = 0;
    if (at < size)
      res = afm_fap_reader_feed(&reader, data + at, size - at, &used, slot, &has);
    else
      res = afm_fap_reader_finish(&reader, slot, &has);
    at += used;
    if (has) {
      if (frames && count >= max_frames) too_small = 1;
      if (count != 0xFFFFFFFFu) ++count;
    }
    if (res != AFM_OK) break;
    if (at >= size && !has && reader.state == ST_FINISHED) break;
  }
  *frame_count = count;
  if (header && afm_fap_reader_header(&reader)) *header = reader.header;
  if (stats) *stats = reader.stats;
  if (res == AFM_OK && too_small) res = AFM_ERR_BUFFER_TOO_SMALL;
  return res;
}
