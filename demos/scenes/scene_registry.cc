#include "demos/scenes/scene.h"
#include "demos/scenes/tet_beam_scene.h"

namespace taut {

const std::vector<SceneInfo>& SceneRegistry() {
  static const std::vector<SceneInfo> scenes = {
      {"tet_beam", "paper A Fig. 2 cantilever: 240-tet beams, E = 200 kPa and 5 kPa", 480,
       1.0 / 240.0,
       [] { return std::make_unique<TetBeamScene>(TetBeamScene::DefaultBeams()); }},
  };
  return scenes;
}

}  // namespace taut
