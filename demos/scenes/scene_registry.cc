#include "demos/scenes/armadillo_scene.h"
#include "demos/scenes/falling_sphere_scene.h"
#include "demos/scenes/hex_beam_scene.h"
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
       120, 1.0 / 240.0,
       [] { return std::make_unique<VerticalBeamScene>(VerticalBeamScene::AllModes()); }},
      {"falling_sphere",
       "paper B Fig. 4: 32-hex spheres (R = 1 m) dropped 2 m onto the ground: 150 kPa, 1 MPa, "
       "150 kPa with U_e <= 500 J",
       480, 1.0 / 240.0,
       [] { return std::make_unique<FallingSphereScene>(FallingSphereScene::DefaultSpheres()); }},
      {"armadillo",
       "paper B Fig. 6: the 2 m Stanford armadillo, 368 hexes, dropped on the ground: 500 kPa, "
       "5 MPa, 500 kPa with U_e <= 100 J (needs scripts/fetch_armadillo.sh)",
       480, 1.0 / 240.0,
       [] { return std::make_unique<ArmadilloScene>(ArmadilloScene::DefaultMaterials()); }},
      {"hex_beam",
       "paper B Fig. 3 cylindrical 56-hex beams: 150 kPa linear, U_e <= 1.0 / 0.5 / 0.1 J, "
       "2 MPa linear",
       480, 1.0 / 240.0,
       [] { return std::make_unique<HexBeamScene>(HexBeamScene::DefaultBeams()); }},
  };
  return scenes;
}

}  // namespace taut
