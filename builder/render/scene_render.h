// Pictures of a scene: its parts as shaded meshes, its FDPs as dots.
//
// A thin C++ layer over afm/render.h (ports/osmesa) for tools and tests:
// converts Scene parts to render meshes (per-vertex colours where a part has
// them, else its diffuse colour), lays several views side by side and
// writes one PNG.
#pragma once

#include <Eigen/Core>
#include <afm/render.h>
#include <cstdint>
#include <string>
#include <vector>

#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

struct SceneView {
  float yaw_deg = 0;    // positive: the camera moves toward the face's left (+x)
  float pitch_deg = 0;  // positive: the camera moves up and looks down
};

// Extra points drawn over the scene as unlit square dots (overlays: key
// points, lines drawn as dense dots).
struct SceneMarkers {
  Eigen::MatrixXd points;                    // #P x 3, model units
  Eigen::Vector3f color{1.0f, 1.0f, 1.0f};   // RGB in [0,1]
  float size_pixels = 3.0f;
  // Pulls the dots toward the viewer by this many model units so those lying
  // on a surface are not hidden by it; 0: 1 % of the diagonal of the box of
  // the scene's parts.
  float depth_bias = 0.0f;
};

struct SceneRenderOptions {
  int width = 600, height = 720;  // of each view
  std::vector<SceneView> views{SceneView{}, SceneView{40.0f, 5.0f}};
  bool wireframe = false;       // triangle edges over the skin
  float fdp_dot_pixels = 7.0f;  // size of FDP dots when FDPs are given; 0 draws none
  // Frame only the face (the FDPs' box without the ears, skull top and
  // spine, grown to hold the markers) instead of every part. Needs FDPs.
  bool face_closeup = false;
  std::vector<SceneMarkers> markers;  // drawn after the FDPs, in order
};

// Renders each view into an RGBA8 image (top row first), in order. With
// `renderer` (afm/render.h: not owned, used from this thread only) the views
// are drawn with it instead of with a renderer made for this call: a series
// of pictures then makes one OSMesa context and compiles its shaders once
// (afm-build --report on Song, the report's 142 pictures: 11.4-12.2 ->
// 7.9-8.2 s in all, alternating runs).
Expected<std::vector<std::vector<uint8_t>>> render_scene(const Scene &scene, const FdpSet *fdps,
                                                         const SceneRenderOptions &options,
                                                         afm_renderer *renderer = nullptr);

// Renders the views side by side into one PNG (atomic).
Status render_scene_png(const Scene &scene, const FdpSet *fdps, const SceneRenderOptions &options,
                        const std::string &path);

}  // namespace afmb
