// The reference head's shape: an implicit surface plus the design numbers
// the mesher and the FDP placement share.
//
// Metres, MPEG-4 neutral frame (+x the face's own left, +y up, +z gaze).
// The origin is between the pupils at pupil height; the head is symmetric
// in x. Proportions follow adult anthropometric means: pupils 63 mm apart,
// iris 11.8 mm, mouth 50 mm wide, subnasale 38 mm below the pupils, stomion
// 20 mm below the subnasale, vertex-to-chin 231 mm, head 150 mm wide.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace afmb::refhead {

using Vec3 = Eigen::Vector3d;

struct HeadDesign {
  // Eyes (the left eye; the right one mirrors it in x).
  Vec3 eye_centre{0.0315, 0.0, 0.066};
  double eye_radius = 0.0122;
  double iris_radius = 0.0059;   // 11.8 mm iris
  double pupil_radius = 0.00197; // a third of the iris diameter (MPEG-4 neutral)
  double lid_thickness = 0.0016; // the lids wrap the eyeball this far out
  // Lid margins curl in to rest this far off the eyeball (more on coarse
  // meshes, whose flat triangles would otherwise cut into it).
  double lid_gap = 0.0003;

  // Mouth: the slit (stomion line) is at y = mouth_y, its corners at
  // x = +-mouth_half_width.
  double mouth_y = -0.060;
  double mouth_half_width = 0.025;
  // The bottom middle of the nose (subnasale, FDP 9.15), where the
  // columella meets the upper lip; the mesher puts a row of vertices here.
  double subnasale_y = -0.0395;

  // The ray parametrisation of the skin: horizontal rays from the vertical
  // axis x = 0, z = axis_z below cap_y; rays from (0, cap_y, axis_z) above.
  double neck_bottom_y = -0.200;
  double cap_y = 0.035;
  double axis_z = -0.012;

  // Where the eye openings' corners are aimed (left eye), as points whose
  // ray directions fix the corners' longitudes; the corners sit on the
  // mouth-like "eye row" at the pupils' height.
  Vec3 eye_inner_corner{0.0205, 0.0, 0.073};
  Vec3 eye_outer_corner{0.0445, 0.0, 0.063};
  // Hairline and brow guide points (left side), used for colours and FDPs.
  double brow_inner_x = 0.015, brow_peak_x = 0.033, brow_outer_x = 0.052;
  double brow_inner_y = 0.019, brow_peak_y = 0.027, brow_outer_y = 0.021;
  double hairline_y = 0.080;      // on the midline
};

const HeadDesign &head_design();

// Signed distance-like value of the skin surface (negative inside).
double head_sdf(const Vec3 &p);
// Outward unit normal by central differences.
Vec3 head_normal(const Vec3 &p);

// A point in the left ear's own frame: (u along the ear, upward and a
// little back; v across it, backward (and outward) positive; w its outward
// normal, lateral and a little forward), with
// the origin at the ear's middle. For x < 0 mirror the point first.
Vec3 ear_local(const Vec3 &p);

// The vermilion (red lip) border on the face at longitude-free terms: for a
// point with |x| = ax, the heights of the upper and lower borders, or false
// when ax is beyond the mouth corners.
bool lip_borders(double ax, double *upper_y, double *lower_y);

// Height of the painted hairline at longitude phi (atan2(x, z - axis_z)):
// 0.08 m on the forehead's midline, lower over the temples, in front of and
// around the ears, lowest at the nape.
double hairline_y(double phi);

// Per-vertex skin colour (linear RGB in [0,1]) from the position: skin tone,
// redder lips, darker brows and nostrils, short hair painted on the scalp.
Vec3 skin_colour(const Vec3 &p);

}  // namespace afmb::refhead
