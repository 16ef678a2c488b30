#include "demos/scenes/armadillo_scene.h"
#include "demos/scenes/box_on_sphere_scene.h"
#include "demos/scenes/collapsing_sphere_scene.h"
#include "demos/scenes/falling_sphere_scene.h"
#include "demos/scenes/finger_scene.h"
#include "demos/scenes/gripper_scene.h"
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
      {"finger",
       "paper A Fig. 3: a 7 cm, 378-tet finger (E = 2 MPa) pressed with 40 N by a kinematic bone "
       "onto a table flat, on its side and on its tip, anisotropic vs isotropic limits, one "
       "press after another",
       520, 1e-3, [] { return std::make_unique<FingerScene>(FingerScene::DefaultPresses()); }},
      {"collapsing_sphere",
       "paper B Fig. 5: 280-hex spheres (R = 1 m, Y = 50 kPa) dropped 0.5 m onto the ground, "
       "without and with U_e <= 50 J",
       360, 1.0 / 240.0,
       [] {
         return std::make_unique<CollapsingSphereScene>(CollapsingSphereScene::DefaultSpheres());
       }},
      {"box_on_sphere",
       "three rigid boxes (20, 10, 5 kg) stacked on a soft 32-hex sphere (500 kPa, U_e <= 0.5 J) "
       "on the ground: rigid-rigid contacts inside the deformable island",
       480, 1.0 / 240.0, [] { return std::make_unique<BoxOnSphereScene>(); }},
      {"gripper",
       "a two-finger btMultiBody gripper (prismatic joints with motors, 15 N per finger) squeezes "
       "a soft strain-limited 384-tet cube (100 kPa, stretch in [0.9, 1.1]) and lifts it 5 cm "
       "off the ground: links, motors and the cube in one island",
       288, 1.0 / 240.0, [] { return std::make_unique<GripperScene>(); }},
  };
  return scenes;
}

}  // namespace taut
