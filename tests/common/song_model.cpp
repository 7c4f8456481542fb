#include "song_model.h"

#include <gtest/gtest.h>

#include "test_paths.h"

namespace afmtest {

SongOnSimMesh song_on_sim_mesh(const std::vector<std::string> &muscles, bool jaw, int vertices,
                               const afmb::TissueParams &tissue, double short_edge) {
  SongOnSimMesh out;
  afmb::Expected<afmb::LoadedFace> f = afmb::load_face(
      shared_data("faces/song/song.WRL"), shared_data("faces/song/song.fdp"), afmb::LoadOptions{}, nullptr);
  EXPECT_TRUE(f.is_ok()) << f.status().message();
  if (!f.is_ok()) return out;
  out.face = std::move(*f);
  afmb::FaceModelOptions fo;
  fo.tissue = tissue;
  fo.calibrate_only = muscles;
  fo.calibrate_muscles = !muscles.empty();
  fo.calibrate_jaw = jaw;
  afmb::SimMeshOptions so{vertices};
  so.short_edge = short_edge;
  afmb::Expected<afmb::SimFaceModel> m = afmb::build_sim_face_model(out.face.scene, out.face.fdps, so, fo);
  EXPECT_TRUE(m.is_ok()) << m.status().message();
  if (m.is_ok()) out.built = std::move(*m);
  return out;
}

}  // namespace afmtest
