/* Fixed-point types and helpers of the player core.
 *
 * The Q format is in the type name: afm_q14 holds value * 2^14. All
 * arithmetic is integer, so a soft-float ARM and an x86 produce the same bits.
 * Right shifts of negative values are arithmetic (floor); every compiler the
 * project targets does this, and afm_player_init checks it at run time.
 */
#ifndef AFM_FIXED_H
#define AFM_FIXED_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef int16_t afm_q14; /* unit vectors, rotation matrix entries: [-2, 2) */
typedef int16_t afm_q12; /* morph target weights: [-8, 8) */
typedef int32_t afm_q16; /* interpolation factors, control gains: [-32768, 32768) */

#define AFM_Q14_ONE 16384
#define AFM_Q12_ONE 4096
#define AFM_Q16_ONE 65536

/* The one saturating conversion: clamps to [-32767, 32767]. (-32768 is left
 * out so that negation never overflows.) */
static inline int16_t afm_saturate16(int32_t v) {
  return (int16_t)(v > 32767 ? 32767 : v < -32767 ? -32767 : v);
}

/* x / 2^k rounded to nearest, halves up (floor(x / 2^k + 1/2)); 1 <= k <= 30.
 * x + 2^(k-1) must not overflow. */
static inline int32_t afm_round_shift32(int32_t x, int k) {
  return (x + ((int32_t)1 << (k - 1))) >> k;
}
static inline int64_t afm_round_shift64(int64_t x, int k) {
  return (x + ((int64_t)1 << (k - 1))) >> k;
}

/* sin and cos of an angle in AU (1e-5 rad), Q14. Quarter-wave table of 1025
 * entries with linear interpolation; error below 1 LSB (6.1e-5). */
afm_q14 afm_sin_au(int32_t angle_au);
afm_q14 afm_cos_au(int32_t angle_au);

#ifdef __cplusplus
}
#endif

#endif /* AFM_FIXED_H */
