#include "demos/scenes/scene.h"
#include "demos/scenes/tet_beam_scene.h"
#include "demos/scenes/vertical_beam_scene.h"

namespace taut {

const std::vector<SceneInfo>& SceneRegistry() {
  static const std::vector<SceneInfo> scenes = {
      {"tet_beam",
       "paper A Fig. 2 cantilever, 240-tet beams: stiff 200 kPa, soft 5 kPa, soft anisotropic, "
       "soft isotropic",
       480, 1.0 / 240.0,
       [] { return std::make_unique<TetBeamScene>(TetBeamScene::DefaultBeams()); }},
      {"vertical_beam",
       "paper A Fig. 4 column (10 kPa) collapsing, x limited to 5 %, in all four projection modes",
       480, 1.0 / 240.0,
       [] { return std::make_unique<VerticalBeamScene>(VerticalBeamScene::AllModes()); }},
  };
  return scenes;
}

}  // namespace taut
