#include "reference_model.h"

#include <gtest/gtest.h>

namespace afmtest {

std::unique_ptr<ReferenceModel> build_reference_model(int skin_vertices, const afmb::FaceModelOptions &options) {
  afmb::RefHeadOptions o;
  o.skin_vertices = skin_vertices;
  afmb::Expected<afmb::RefHead> h = afmb::make_reference_head(o);
  EXPECT_TRUE(h.is_ok()) << h.status().message();
  if (!h) return nullptr;
  afmb::Expected<afmb::FaceModel> m = afmb::build_face_model(h->scene, h->fdps, options);
  EXPECT_TRUE(m.is_ok()) << m.status().message();
  if (!m) return nullptr;
  return std::make_unique<ReferenceModel>(ReferenceModel{std::move(*h), std::move(*m)});
}

}  // namespace afmtest
