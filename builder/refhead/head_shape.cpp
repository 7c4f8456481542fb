#include "refhead/head_shape.h"

#include <algorithm>
#include <cmath>

#include "refhead/sdf.h"

namespace afmb::refhead {

using namespace afmb::sdf;

const HeadDesign &head_design() {
  static const HeadDesign design;
  return design;
}

namespace {

// Lips, mouth groove and lip colour follow the dental arch: evaluating them
// at z + kArch * x^2 bends straight shapes around it.
constexpr double kArch = 30.0;
constexpr double kPi = 3.14159265358979323846;

double bend(const Vec3 &q) { return q.z() + kArch * q.x() * q.x(); }

// The ear in its own frame: origin at the ear's centre, u along its length
// (tilted back), w its outward normal (turned a little backward), v = u x w.
struct EarFrame {
  Vec3 origin{0.0770, -0.011, -0.016};
  Vec3 u, v, w;
  EarFrame() {
    // The ear faces out and a little forward, so its front edge sinks into
    // the head and its back rim stands off it, as an auricle does.
    const double tilt = 0.26, turn = -0.55;  // radians
    u = Vec3(0.0, std::cos(tilt), -std::sin(tilt));
    w = Vec3(std::cos(turn), 0.0, -std::sin(turn));
    w = (w - w.dot(u) * u).normalized();
    v = u.cross(w);
  }
  Vec3 local(const Vec3 &q) const {
    Vec3 d = q - origin;
    return Vec3(d.dot(u), d.dot(v), d.dot(w));
  }
};
const EarFrame &ear_frame() {
  static const EarFrame frame;
  return frame;
}

double ear(const Vec3 &q) {
  Vec3 l = ear_frame().local(q);
  if (l.squaredNorm() > 0.05 * 0.05) return l.norm() - 0.035;  // far: a cheap bound
  // The lower half bends in to the head: an attached lobe, whose underside
  // faces out enough for the rays that build the skin to see it.
  if (l.x() < 0) l.z() += 16.0 * l.x() * l.x();
  // Shell: an oval plate, wider at the top, standing off the head.
  double shell = ellipsoid(l, Vec3(0.002, 0.0, 0.0), Vec3(0.031, 0.0165, 0.0095));
  double lobe = ellipsoid(l, Vec3(-0.021, 0.002, 0.0005), Vec3(0.010, 0.009, 0.0065));
  double d = smin(shell, lobe, 0.006);
  // Bowl inside the helix rim (scapha and fossa), then the deeper concha in
  // front, by the ear canal (v < 0 is forward).
  double bowl = ellipsoid(l, Vec3(0.005, 0.001, 0.0105), Vec3(0.021, 0.0115, 0.0065));
  d = ssub(d, bowl, 0.0025);
  double concha = ellipsoid(l, Vec3(-0.005, -0.004, 0.0085), Vec3(0.0085, 0.0065, 0.0070));
  d = ssub(d, concha, 0.002);
  // Antihelix ridge between the bowl and the concha.
  double antihelix = capsule(l, Vec3(0.014, 0.004, 0.0035), Vec3(-0.004, 0.003, 0.004),
                             0.0022, 0.0026);
  d = smin(d, antihelix, 0.002);
  // Behind the ear, a web down to the head: the rays that build the skin
  // would otherwise pass behind the rim and leave a cliff of slivers.
  const double web = ellipsoid(l, Vec3(-0.002, 0.006, -0.010), Vec3(0.027, 0.014, 0.011));
  return smin(d, web, 0.006);
}

double nose(const Vec3 &q) {
  const double bridge = capsule(q, Vec3(0.0, 0.012, 0.081), Vec3(0.0, -0.018, 0.1005), 0.0062,
                                0.0080);
  const double tip = ellipsoid(q, Vec3(0.0, -0.0228, 0.1025), Vec3(0.0095, 0.0085, 0.0095));
  const double body = ellipsoid(q, Vec3(0.0, -0.0178, 0.086), Vec3(0.0105, 0.0185, 0.0125));
  const double ala = ellipsoid(q, Vec3(0.0120, -0.0268, 0.0885), Vec3(0.0062, 0.0062, 0.0078));
  double d = smin(bridge, tip, 0.008);
  d = smin(d, body, 0.008);
  d = smin(d, ala, 0.0045);
  // Columella and the nostrils either side of it, opening downward.
  const double nostril = ellipsoid(q, Vec3(0.0062, -0.0315, 0.0965), Vec3(0.0034, 0.0024, 0.0058));
  d = ssub(d, nostril, 0.0015);
  return d;
}

double lips(const Vec3 &q, double y_mouth) {
  Vec3 b(q.x(), q.y(), bend(q));
  const double upper = ellipsoid(b, Vec3(0.0, -0.0535, 0.0915), Vec3(0.0262, 0.0072, 0.0098));
  const double lower = ellipsoid(b, Vec3(0.0, -0.0675, 0.0890), Vec3(0.0228, 0.0080, 0.0098));
  double d = smin(upper, lower, 0.002);
  // Philtrum: a shallow groove from the nose to the cupid's bow.
  const double philtrum = capsule(b, Vec3(0.0, -0.0405, 0.0955), Vec3(0.0, -0.0500, 0.1005),
                                  0.0016, 0.0016);
  d = ssub(d, philtrum, 0.003);
  // The groove where the lips meet; the mesher cuts the slit along it.
  const double groove = capsule(b, Vec3(-0.028, y_mouth, 0.0985), Vec3(0.028, y_mouth, 0.0985),
                                0.0012, 0.0012);
  return ssub(d, groove, 0.0025);
}

}  // namespace

Vec3 ear_local(const Vec3 &p) { return ear_frame().local(p); }

// Blends a shape into d, or carves it out, skipping the shape when a bound
// from its bounding sphere (centre c, radius r, with a margin for the
// approximate ellipsoid distance) shows it cannot change the result: most
// of the head is far from most features, and this is the hot path.
template <class F>
double add(double d, const Vec3 &q, const Vec3 &c, double r, double k, F shape) {
  if ((q - c).norm() - 1.25 * r > d + k) return d;
  return smin(d, shape(), k);
}
template <class F>
double cut(double d, const Vec3 &q, const Vec3 &c, double r, double k, F shape) {
  if ((q - c).norm() - 1.25 * r > k - d) return d;
  return ssub(d, shape(), k);
}

double head_sdf(const Vec3 &p) {
  const HeadDesign &hd = head_design();
  const Vec3 q(std::abs(p.x()), p.y(), p.z());
  auto E = [&q](const Vec3 &c, const Vec3 &r) { return [&q, c, r] { return ellipsoid(q, c, r); }; };

  // Skull masses.
  double d = ellipsoid(q, Vec3(0.0, 0.028, -0.014), Vec3(0.0745, 0.093, 0.097));  // cranium
  d = add(d, q, Vec3(0.0, -0.018, 0.030), 0.060, 0.03,
          E(Vec3(0.0, -0.018, 0.030), Vec3(0.060, 0.060, 0.057)));  // midface
  d = add(d, q, Vec3(0.0, -0.059, 0.052), 0.038, 0.015,
          E(Vec3(0.0, -0.059, 0.052), Vec3(0.037, 0.029, 0.038)));  // muzzle

  // Mandible: a rounded mass cut from below by the plane through the jaw
  // angles and the bottom of the chin, which makes the jaw line; then the
  // chin. (Smooth unions add up to k/4 where shapes meet, so blends stay
  // small here.)
  d = add(d, q, Vec3(0.0, -0.062, 0.020), 0.075, 0.01, [&] {
    const Vec3 n = Vec3(0.0, 0.075, 0.034).normalized();  // up and forward
    const double below = -n.dot(q - Vec3(0.0, -0.0805, 0.0));
    const double mass = ellipsoid(q, Vec3(0.0, -0.062, 0.020), Vec3(0.0540, 0.058, 0.064));
    const double jaw = smin(
        mass, ellipsoid(q, Vec3(0.0, -0.0950, 0.0745), Vec3(0.0250, 0.0175, 0.0170)), 0.012);
    return smax(jaw, below, 0.02);
  });

  // Cheeks, cheekbones, zygomatic arches.
  d = add(d, q, Vec3(0.035, -0.033, 0.057), 0.023, 0.02,
          E(Vec3(0.035, -0.033, 0.057), Vec3(0.020, 0.023, 0.023)));
  d = add(d, q, Vec3(0.046, -0.013, 0.055), 0.021, 0.015,
          E(Vec3(0.046, -0.013, 0.055), Vec3(0.020, 0.012, 0.021)));
  d = add(d, q, Vec3(0.0595, -0.0095, 0.024), 0.026, 0.02, [&] {
    return capsule(q, Vec3(0.056, -0.011, 0.044), Vec3(0.063, -0.008, 0.004), 0.0050, 0.0040);
  });

  // Brow ridge and glabella.
  d = add(d, q, Vec3(0.026, 0.020, 0.076), 0.030, 0.010, [&] {
    return capsule(q, Vec3(0.006, 0.0185, 0.0835), Vec3(0.046, 0.022, 0.069), 0.0080, 0.0060);
  });
  d = add(d, q, Vec3(0.0, 0.017, 0.081), 0.016, 0.008,
          E(Vec3(0.0, 0.017, 0.081), Vec3(0.016, 0.010, 0.0095)));

  // Temples, then the eye sockets with the lids wrapped around the eyeballs.
  d = cut(d, q, Vec3(0.077, 0.030, 0.044), 0.018, 0.02,
          E(Vec3(0.077, 0.030, 0.044), Vec3(0.008, 0.018, 0.018)));
  d = cut(d, q, Vec3(0.0325, 0.002, 0.079), 0.0195, 0.007,
          E(Vec3(0.0325, 0.002, 0.079), Vec3(0.0195, 0.0135, 0.0165)));
  d = add(d, q, hd.eye_centre, hd.eye_radius + hd.lid_thickness, 0.003,
          [&] { return sphere(q, hd.eye_centre, hd.eye_radius + hd.lid_thickness); });

  // Nose, lips, ears.
  d = add(d, q, Vec3(0.0, -0.010, 0.092), 0.030, 0.006, [&] { return nose(q); });
  d = add(d, q, Vec3(0.0, -0.058, 0.085), 0.032, 0.005, [&] { return lips(q, hd.mouth_y); });
  d = add(d, q, ear_frame().origin, 0.040, 0.004, [&] { return ear(q); });

  // Neck: a long ellipsoid rising into the head, and the soft tissue from
  // the chin down to the throat (a wide, flattened capsule): it keeps the
  // underside of the chin from hiding behind the jaw line.
  if (q.y() - (-0.025) <= d + 0.05)
    d = smin(d, ellipsoid(q, Vec3(0.0, -0.250, -0.011), Vec3(0.055, 0.225, 0.056)), 0.05);
  d = add(d, q, Vec3(0.0, -0.125, 0.042), 0.06, 0.015, [&] {
    const Vec3 s(q.x() * 0.5, q.y(), q.z());
    return capsule(s, Vec3(0.0, -0.100, 0.058), Vec3(0.0, -0.150, 0.026), 0.013, 0.015);
  });
  return d;
}

Vec3 head_normal(const Vec3 &p) {
  const double h = 1e-5;
  Vec3 g(head_sdf(p + Vec3(h, 0, 0)) - head_sdf(p - Vec3(h, 0, 0)),
         head_sdf(p + Vec3(0, h, 0)) - head_sdf(p - Vec3(0, h, 0)),
         head_sdf(p + Vec3(0, 0, h)) - head_sdf(p - Vec3(0, 0, h)));
  double n = g.norm();
  return n > 0 ? Vec3(g / n) : Vec3(0, 0, 1);
}

bool lip_borders(double ax, double *upper_y, double *lower_y) {
  const HeadDesign &hd = head_design();
  const double w = hd.mouth_half_width;
  if (ax >= w) return false;
  const double s = ax / w;  // 0 at the middle, 1 at a corner
  // Upper border: cupid's bow, peaks at s = 0.22, a dip in the middle.
  const double bow = 0.0014 * std::exp(-std::pow((s - 0.22) / 0.13, 2)) -
                     0.0008 * std::exp(-std::pow(s / 0.09, 2));
  *upper_y = hd.mouth_y + 0.0075 * std::pow(1.0 - s * s, 0.75) + bow;
  *lower_y = hd.mouth_y - 0.0095 * std::pow(1.0 - s * s, 0.85);
  return true;
}

double hairline_y(double phi) {
  // Height of the hairline by longitude (0 ahead, pi behind), through key
  // points: forehead, temple corner, above the sideburn, its lower end,
  // over the ear, behind the ear, the nape.
  const double a = std::abs(phi);
  struct Key {
    double phi, y;
  };
  static const Key keys[] = {{0.0, 0.080},  {0.30, 0.076}, {0.62, 0.063}, {1.25, 0.040},
                             {1.38, 0.004}, {1.47, 0.004}, {1.60, 0.030}, {2.10, 0.024},
                             {2.40, -0.030}, {2.70, -0.042}, {3.1416, -0.046}};
  for (size_t i = 1; i < sizeof keys / sizeof keys[0]; ++i) {
    if (a <= keys[i].phi) {
      const double t = smoothstep(keys[i - 1].phi, keys[i].phi, a);
      return keys[i - 1].y + t * (keys[i].y - keys[i - 1].y);
    }
  }
  return keys[sizeof keys / sizeof keys[0] - 1].y;
}

Vec3 skin_colour(const Vec3 &p) {
  const HeadDesign &hd = head_design();
  const double ax = std::abs(p.x());
  Vec3 skin(0.86, 0.66, 0.55);
  const Vec3 lip(0.72, 0.36, 0.37);
  const Vec3 brow(0.30, 0.21, 0.16);
  const Vec3 dark(0.30, 0.17, 0.15);

  // Lips: inside the vermilion borders, on the front of the face.
  double up = 0, lo = 0;
  if (p.z() > 0.05 && lip_borders(ax, &up, &lo)) {
    const double soft = 0.0014;
    double t = smoothstep(-soft, soft, up - p.y()) * smoothstep(-soft, soft, p.y() - lo);
    skin = skin + t * (lip - skin);
  }
  // A faint blush on the cheeks.
  {
    double r = (Vec3(ax, p.y(), p.z()) - Vec3(0.045, -0.030, 0.070)).norm();
    skin = skin + 0.25 * (1.0 - smoothstep(0.0, 0.022, r)) * (Vec3(0.85, 0.55, 0.50) - skin);
  }
  // Brows: an arch from the inner end over the peak to the outer end.
  if (p.z() > 0.03 && ax > hd.brow_inner_x - 0.004 && ax < hd.brow_outer_x + 0.006) {
    double xs = ax, yc;
    if (xs < hd.brow_peak_x) {
      double s = (xs - hd.brow_inner_x) / (hd.brow_peak_x - hd.brow_inner_x);
      yc = hd.brow_inner_y + (hd.brow_peak_y - hd.brow_inner_y) * std::sin(0.5 * kPi * std::clamp(s, 0.0, 1.0));
    } else {
      double s = (xs - hd.brow_peak_x) / (hd.brow_outer_x - hd.brow_peak_x);
      yc = hd.brow_peak_y + (hd.brow_outer_y - hd.brow_peak_y) * std::clamp(s, 0.0, 1.2) * std::clamp(s, 0.0, 1.2);
    }
    // Thicker at the inner end, tapering outward.
    double half = 0.0042 - 0.0018 * smoothstep(hd.brow_inner_x, hd.brow_outer_x, xs);
    double along = smoothstep(hd.brow_inner_x - 0.004, hd.brow_inner_x + 0.002, xs) *
                   (1.0 - smoothstep(hd.brow_outer_x - 0.002, hd.brow_outer_x + 0.006, xs));
    double t = along * (1.0 - smoothstep(half * 0.3, half * 1.3, std::abs(p.y() - yc)));
    skin = skin + 0.65 * t * (brow - skin);
  }
  // Short hair, painted: above a hairline that runs from the forehead over
  // the temples, down in front of the ears as sideburns, over the ears and
  // down to the nape. It reads as a person rather than a mannequin, and
  // makes FDPs 11.1-11.3 (the hair's border with the forehead) visible.
  {
    const double y_hair = hairline_y(std::atan2(ax, p.z() - hd.axis_z));
    double t = smoothstep(y_hair - 0.0025, y_hair + 0.0025, p.y());
    // Not on the ears themselves.
    const Vec3 l = ear_local(Vec3(ax, p.y(), p.z()));
    if (std::pow(l.x() / 0.036, 2) + std::pow(l.y() / 0.021, 2) < 1.0 && l.z() > -0.006) t = 0.0;
    skin = skin + 0.92 * t * (Vec3(0.20, 0.14, 0.10) - skin);
  }
  // Nostrils: dark inside the openings under the nose.
  {
    double r = ((Vec3(ax, p.y(), p.z()) - Vec3(0.0062, -0.0315, 0.0965))
                    .cwiseQuotient(Vec3(0.0036, 0.0028, 0.0060)))
                   .norm();
    skin = skin + (1.0 - smoothstep(0.7, 1.05, r)) * (dark - skin);
  }
  return skin;
}

}  // namespace afmb::refhead
