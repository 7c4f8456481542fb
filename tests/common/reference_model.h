// The procedural reference head and its anatomical model, for the tests
// that need a face model (tests/anatomy, tests/fap).
#pragma once

#include <memory>

#include "anatomy/face_model.h"
#include "refhead/refhead.h"

namespace afmtest {

struct ReferenceModel {
  afmb::RefHead head;
  afmb::FaceModel model;
};

// The reference head at `skin_vertices` and its model built with `options`;
// records a test failure and returns null when either fails.
std::unique_ptr<ReferenceModel> build_reference_model(int skin_vertices, const afmb::FaceModelOptions &options);

}  // namespace afmtest
