// Every kind of bad user input throws InputError saying what is wrong and where (body, mesh,
// file:line, element, node, axis): materials, body settings, strain and energy limits, meshes and
// lattices, truncated files of every reader, surfaces for voxelization, node indices and states.
#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "constraints/energy_limits.h"
#include "constraints/sqp_settings.h"
#include "constraints/strain_limits.h"
#include "demos/scenes/bullet_world_holder.h"
#include "plugin/box_tet_mesher.h"
#include "plugin/deformable_body.h"
#include "plugin/gmsh_reader.h"
#include "plugin/hex_element_model.h"
#include "plugin/hex_voxelizer.h"
#include "plugin/obj_surface_reader.h"
#include "plugin/off_reader.h"
#include "plugin/tet_element_model.h"
#include "plugin/tetgen_reader.h"
#include "plugin/vtk_reader.h"

namespace taut {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Expects fn() to throw InputError whose message contains every one of parts.
template <typename Fn>
void ExpectInputError(Fn&& fn, const std::vector<std::string>& parts) {
  try {
    fn();
    ADD_FAILURE() << "no InputError; expected one mentioning '" << *parts.begin() << "'";
  } catch (const InputError& e) {
    const std::string what = e.what();
    for (const std::string& part : parts)
      EXPECT_NE(what.find(part), std::string::npos) << what << "\n  expected: " << part;
  }
}

// A valid 1 m cube body "cube" (2 x 2 x 2 cells, 27 nodes) made with `settings` (name forced).
std::unique_ptr<DeformableBody> MakeCube(DeformableBodySettings settings = {}) {
  settings.name = "cube";
  auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(1, 1, 1), 2, 2, 2));
  return std::make_unique<DeformableBody>(std::make_unique<TetElementModel>(mesh, Material{}),
                                          settings);
}

// ---- Materials (Material::Validate through the body settings and the element model) ----

// Expects `material` to be rejected naming the body and the quantity.
void ExpectBadMaterial(const Material& material, const std::string& quantity) {
  DeformableBodySettings settings;
  settings.material = material;
  ExpectInputError([&] { MakeCube(settings); }, {"body 'cube'", quantity});
}

TEST(BadInputTest, YoungsModulusMustBeFiniteAndPositive) {
  for (double E : {0.0, -1e5, kNan, kInf}) ExpectBadMaterial({E, 0.3, 1000}, "Young's modulus");
}

TEST(BadInputTest, PoissonRatioMustLieInMinusOneToHalf) {
  for (double nu : {-1.0, -1.5, 0.5, 0.7, kNan}) ExpectBadMaterial({1e5, nu, 1000}, "Poisson");
}

TEST(BadInputTest, DensityMustBeFiniteAndPositive) {
  for (double rho : {0.0, -1.0, kNan, kInf}) ExpectBadMaterial({1e5, 0.3, rho}, "density");
}

TEST(BadInputTest, ElementModelNamesTheMeshOfABadMaterial) {
  auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(1, 1, 1), 1, 1, 1));
  mesh->source = "beam.msh";
  ExpectInputError(
      [&] {
        TetElementModel model(mesh, Material{-1.0, 0.3, 1000});
      },
      {"beam.msh", "Young's modulus", "-1"});
  auto lattice = std::make_shared<HexLattice>(MakeBoxHexLattice(Vec3(1, 1, 1), 1, 1, 1));
  ExpectInputError(
      [&] {
        HexElementModel model(lattice, Material{1e5, 0.5, 1000});
      },
      {lattice->source, "Poisson"});
}

// ---- Body settings ----

TEST(BadInputTest, DampingMustBeFiniteAndNonNegative) {
  for (double bad : {-0.1, kNan, kInf}) {
    DeformableBodySettings alpha, beta;
    alpha.mass_damping = bad;
    beta.stiffness_damping = bad;
    ExpectInputError([&] { MakeCube(alpha); }, {"body 'cube'", "mass damping"});
    ExpectInputError([&] { MakeCube(beta); }, {"body 'cube'", "stiffness damping"});
  }
}

TEST(BadInputTest, FrictionMustBeFiniteAndNonNegative) {
  for (double bad : {-0.5, kNan, kInf}) {
    DeformableBodySettings settings;
    settings.friction = bad;
    ExpectInputError([&] { MakeCube(settings); }, {"body 'cube'", "friction"});
  }
}

TEST(BadInputTest, RestitutionMustLieInZeroToOne) {
  for (double bad : {-0.1, 1.5, kNan, kInf}) {
    DeformableBodySettings settings;
    settings.restitution = bad;
    ExpectInputError([&] { MakeCube(settings); }, {"body 'cube'", "restitution", "[0, 1]"});
  }
  DeformableBodySettings settings;
  settings.restitution = 1.5;
  ExpectInputError([&] { MakeCube(settings); }, {"got 1.5"});
  for (double good : {0.0, 0.5, 1.0}) {
    settings.restitution = good;
    EXPECT_NO_THROW(MakeCube(settings));
  }
}

TEST(BadInputTest, ContactMarginMustBeFiniteAndPositive) {
  for (double bad : {0.0, -0.01, kNan, kInf}) {
    DeformableBodySettings settings;
    settings.contact_margin = bad;
    ExpectInputError([&] { MakeCube(settings); }, {"body 'cube'", "contact margin"});
  }
}

TEST(BadInputTest, MaxSpeedMustBePositiveAndMayBeInfinite) {
  for (double bad : {0.0, -10.0, kNan}) {
    DeformableBodySettings settings;
    settings.max_speed = bad;
    ExpectInputError([&] { MakeCube(settings); }, {"body 'cube'", "max speed"});
  }
  DeformableBodySettings off;
  off.max_speed = kInf;
  EXPECT_EQ(MakeCube(off)->settings().max_speed, kInf);
}

// ---- Strain limits ----

// Expects `limits` (for 6 elements) to be rejected naming where ("body 'cube' strain limits")
// and every part.
void ExpectBadStrainLimits(const StrainLimitSettings& limits, std::vector<std::string> parts) {
  parts.push_back("body 'cube' strain limits");
  ExpectInputError([&] { limits.Validate(6, "body 'cube' strain limits"); }, parts);
}

TEST(BadInputTest, StrainLimitMinAboveMaxIsNamedWithItsAxis) {
  ExpectBadStrainLimits(StrainLimitSettings::PerAxis(Vec3(0.9, 1.5, 0.9), Vec3(1.2, 1.2, 1.2)),
                        {"axis 1", "s_min[1] = 1.5 > s_max[1] = 1.2"});
}

TEST(BadInputTest, StrainLimitMinMustBeZeroOrACompressRatio) {
  for (double bad : {-0.1, 1.0}) {
    ExpectBadStrainLimits(StrainLimitSettings::PerAxis(Vec3(0.9, 0.9, bad), Vec3::Constant(1.1)),
                          {"s_min[2]", "out of range"});
  }
  // 0 is the documented "no compress limit", not an error.
  EXPECT_NO_THROW(StrainLimitSettings::Isotropic(0.0, 1.1).Validate(6, "cube"));
}

TEST(BadInputTest, StrainLimitMaxMustBeAStretchRatioAboveOne) {
  for (double bad : {1.0, 0.5, 0.0, -kInf})
    ExpectBadStrainLimits(StrainLimitSettings::Isotropic(0.9, bad), {"s_max[0]", "out of range"});
}

TEST(BadInputTest, StrainLimitNanIsNamed) {
  ExpectBadStrainLimits(StrainLimitSettings::PerAxis(Vec3(0.9, kNan, 0.9), Vec3::Constant(1.1)),
                        {"s_min[1] is NaN"});
  ExpectBadStrainLimits(StrainLimitSettings::PerAxis(Vec3::Constant(0.9), Vec3(1.1, 1.1, kNan)),
                        {"s_max[2] is NaN"});
}

TEST(BadInputTest, StrainLimitUnknownProjectionIsRejected) {
  StrainLimitSettings limits = StrainLimitSettings::Isotropic(0.9, 1.1);
  limits.projection = static_cast<StrainProjection>(7);
  ExpectBadStrainLimits(limits, {"unknown strain projection 7"});
}

TEST(BadInputTest, StrainLimitFrameMustBeAProperRotation) {
  StrainLimitSettings limits = StrainLimitSettings::Isotropic(0.9, 1.1);
  const Mat3 bad_frames[] = {2.0 * Mat3::Identity(),                          // not unit vectors
                             Mat3::Identity() + 0.1 * Mat3::Ones(),           // not orthogonal
                             Vec3(1, 1, -1).asDiagonal() * Mat3::Identity(),  // reflection
                             Mat3::Constant(kNan)};
  for (const Mat3& frame : bad_frames) {
    limits.frame = frame;
    ExpectBadStrainLimits(limits, {"strain-limit frame", "rotation"});
  }
  limits.frame = Mat3::Identity();
  limits.element_frames.assign(5, Mat3::Identity());
  ExpectBadStrainLimits(limits, {"5 strain-limit element frames given for 6 elements"});
  limits.element_frames.assign(6, Mat3::Identity());
  limits.element_frames[4].col(2) *= -1.0;
  ExpectBadStrainLimits(limits, {"frame of element 4", "not a rotation"});
}

TEST(BadInputTest, StrainLimitCapsMarginAndEpsilonAreChecked) {
  StrainLimitSettings limits = StrainLimitSettings::Isotropic(0.9, 1.1);
  limits.unlimited_s_min_cap = 1.0;
  ExpectBadStrainLimits(limits, {"unlimited_s_min_cap"});
  limits = StrainLimitSettings::Isotropic(0.9, 1.1);
  limits.unlimited_s_max_cap = kInf;
  ExpectBadStrainLimits(limits, {"unlimited_s_max_cap"});
  limits = StrainLimitSettings::Isotropic(0.9, 1.1);
  limits.activation_margin = kNan;
  ExpectBadStrainLimits(limits, {"activation_margin"});
  limits = StrainLimitSettings::Isotropic(0.9, 1.1);
  limits.svd_gap_epsilon = -1e-3;
  ExpectBadStrainLimits(limits, {"svd_gap_epsilon"});
}

// ---- Energy limits ----

TEST(BadInputTest, EnergyLimitMustBePositiveAndNotNan) {
  for (double bad : {0.0, -1.0, kNan}) {
    ExpectInputError([&] { EnergyLimitSettings::PerElementEnergy(bad).Validate(6, "body 'cube'"); },
                     {"body 'cube'", "energy limit u_max", "J is out of range"});
    ExpectInputError([&] { EnergyLimitSettings::EnergyDensity(bad).Validate(6, "body 'cube'"); },
                     {"body 'cube'", "J/m^3 is out of range"});
  }
  ExpectInputError([] { EnergyLimitSettings().Validate(6, "body 'cube'"); }, {"u_max = 0"});
}

TEST(BadInputTest, PerElementEnergyLimitsNameTheElement) {
  EnergyLimitSettings limits;
  limits.element_u_max.assign(5, 1.0);
  ExpectInputError([&] { limits.Validate(6, "body 'cube'"); }, {"5 per-element", "6 elements"});
  limits.element_u_max.assign(6, 1.0);
  limits.element_u_max[3] = kNan;
  ExpectInputError([&] { limits.Validate(6, "body 'cube'"); }, {"energy limit of element 3"});
}

TEST(BadInputTest, EnergyLimitUnitAndMarginAreChecked) {
  EnergyLimitSettings limits = EnergyLimitSettings::PerElementEnergy(1.0);
  limits.unit = static_cast<EnergyLimitUnit>(5);
  ExpectInputError([&] { limits.Validate(6, "body 'cube'"); }, {"unknown energy limit unit 5"});
  limits = EnergyLimitSettings::PerElementEnergy(1.0);
  limits.activation_margin = -0.1;
  ExpectInputError([&] { limits.Validate(6, "body 'cube'"); }, {"activation_margin = -0.1"});
  ExpectInputError(
      [] {
        CalcElementEnergyLimits(EnergyLimitSettings::EnergyDensity(10.0), {1.0, 0.0});
      },
      {"rest volume of element 1"});
}

// ---- Tet meshes and hex lattices ----

// The 6-tet unit cube mesh "cube.ele" with `edit` applied.
template <typename Edit>
std::shared_ptr<TetMesh> EditedCube(Edit&& edit) {
  auto mesh = std::make_shared<TetMesh>(MakeBoxTetMesh(Vec3(1, 1, 1), 1, 1, 1));
  mesh->source = "cube.ele";
  edit(*mesh);
  return mesh;
}

// Expects the element model of `mesh` to be rejected naming the mesh and every part.
void ExpectBadTetMesh(const std::shared_ptr<TetMesh>& mesh, std::vector<std::string> parts) {
  parts.push_back("cube.ele: ");
  ExpectInputError([&] { TetElementModel model(mesh, Material{}); }, parts);
}

TEST(BadInputTest, DegenerateAndInvertedTetsAreNamed) {
  // Node 3 of tet 2 replaced by a new node 1e-15 m from its node 0.
  ExpectBadTetMesh(EditedCube([](TetMesh& m) {
                     m.nodes.push_back(m.nodes[m.tets[2][0]] + 1e-15 * Vec3::Ones());
                     m.tets[2][3] = static_cast<int>(m.nodes.size()) - 1;
                   }),
                   {"element 2 is degenerate"});
  ExpectBadTetMesh(EditedCube([](TetMesh& m) { std::swap(m.tets[4][0], m.tets[4][1]); }),
                   {"element 4 is inverted"});
}

TEST(BadInputTest, TetIndicesOutOfRangeOrRepeatedAreNamed) {
  ExpectBadTetMesh(EditedCube([](TetMesh& m) { m.tets[1][2] = 8; }),
                   {"element 1 refers to node 8 but the mesh has 8 nodes"});
  ExpectBadTetMesh(EditedCube([](TetMesh& m) { m.tets[0][0] = -1; }), {"refers to node -1"});
  ExpectBadTetMesh(EditedCube([](TetMesh& m) { m.tets[3][3] = m.tets[3][1]; }),
                   {"element 3 repeats node"});
}

TEST(BadInputTest, NonFiniteOrMissingTetMeshDataIsNamed) {
  ExpectBadTetMesh(EditedCube([](TetMesh& m) { m.nodes[5].y() = kNan; }),
                   {"node 5 has a non-finite coordinate"});
  ExpectBadTetMesh(EditedCube([](TetMesh& m) { m.nodes[6].z() = kInf; }), {"node 6"});
  ExpectBadTetMesh(EditedCube([](TetMesh& m) { m.tets.clear(); }), {"no tetrahedra"});
}

TEST(BadInputTest, BadHexLatticesAreNamed) {
  auto lattice = [](auto edit) {
    auto l = std::make_shared<HexLattice>(MakeBoxHexLattice(Vec3(1, 1, 1), 2, 1, 1));
    l->source = "lattice";
    edit(*l);
    return l;
  };
  const auto expect = [](const std::shared_ptr<HexLattice>& l, const std::string& part) {
    ExpectInputError([&] { HexElementModel model(l, Material{}); }, {"lattice: ", part});
  };
  // Hex 1 mirrored in x (local nodes a and a + 4 swapped): det dX/ds < 0 everywhere.
  expect(lattice([](HexLattice& l) {
           for (int a = 0; a < 4; ++a) std::swap(l.hexes[1][a], l.hexes[1][a + 4]);
         }),
         "element 1 is inverted");
  // Hex 0 flattened in z (each node a + 1 moved onto node a): det dX/ds = 0.
  expect(lattice([](HexLattice& l) {
           for (int a = 1; a < 8; a += 2) l.nodes[l.hexes[0][a]] = l.nodes[l.hexes[0][a - 1]];
         }),
         "element 0 is degenerate");
  expect(lattice([](HexLattice& l) { l.hexes[1][7] = 99; }), "element 1 refers to node 99");
  expect(lattice([](HexLattice& l) { l.nodes[3].x() = kNan; }), "node 3 has a non-finite");
}

// ---- Mesh files: every reader, truncated, with NaN coordinates, bad indices ----

// Parses text named name with one reader; for surfaces, also demands a closed surface, since a
// truncated OBJ (no counts) can only be caught there.
using ParseFn = void (*)(const std::string& text, const std::string& name);

// A small valid file for each reader, with the name used in messages.
struct ReaderCase {
  const char* name;
  ParseFn parse;
  std::string text;
};

const std::string kTetGenNode = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
const std::string kTetGenEle = "1 4 0\n0 0 1 2 3\n";

std::vector<ReaderCase> ReaderCases() {
  return {
      {"t.node",
       [](const std::string& t, const std::string& n) {
         internal::ParseTetGenMesh(t, n, kTetGenEle, "t.ele");
       },
       kTetGenNode},
      {"t.ele",
       [](const std::string& t, const std::string& n) {
         internal::ParseTetGenMesh(kTetGenNode, "t.node", t, n);
       },
       kTetGenEle},
      {"t22.msh", [](const std::string& t, const std::string& n) { internal::ParseGmshMesh(t, n); },
       "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"
       "$EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n"},
      {"t41.msh", [](const std::string& t, const std::string& n) { internal::ParseGmshMesh(t, n); },
       "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n"
       "1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n"},
      {"classic.vtk",
       [](const std::string& t, const std::string& n) { internal::ParseVtkMesh(t, n); },
       "# vtk DataFile Version 3.0\none tet\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n"
       "0 0 0\n1 0 0\n0 1 0\n0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n"},
      {"v51.vtk", [](const std::string& t, const std::string& n) { internal::ParseVtkMesh(t, n); },
       "# vtk DataFile Version 5.1\none tet\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 float\n"
       "0 0 0 1 0 0\n0 1 0 0 0 1\nCELLS 2 4\nOFFSETS vtktypeint64\n0 4\n"
       "CONNECTIVITY vtktypeint64\n0 1 2 3\nCELL_TYPES 1\n10\n"},
      {"t.off",
       [](const std::string& t, const std::string& n) {
         ValidateClosedSurface(internal::ParseOffSurface(t, n));
       },
       "OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"},
      {"t.obj",
       [](const std::string& t, const std::string& n) {
         ValidateClosedSurface(internal::ParseObjSurface(t, n));
       },
       "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"},
  };
}

TEST(BadInputTest, TruncatedFilesOfEveryReaderAreRejectedNamingTheFile) {
  for (const ReaderCase& c : ReaderCases()) {
    SCOPED_TRACE(c.name);
    ASSERT_NO_THROW(c.parse(c.text, c.name));
    // Every prefix of whole lines, and every cut inside the last line.
    std::vector<std::size_t> cuts;
    for (std::size_t i = 0; i + 1 < c.text.size(); ++i)
      if (c.text[i] == '\n') cuts.push_back(i + 1);
    for (std::size_t i = cuts.back(); i + 1 < c.text.size(); ++i) cuts.push_back(i);
    cuts.push_back(0);
    for (std::size_t cut : cuts) {
      SCOPED_TRACE("cut at byte " + std::to_string(cut));
      ExpectInputError([&] { c.parse(c.text.substr(0, cut), c.name); },
                       {std::string(c.name) + ":"});
    }
  }
}

// Replaces the first occurrence of `from` in text by `to`.
std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(BadInputTest, NanCoordinatesInEveryReaderAreNamedWithTheLine) {
  // The second vertex's x (file line, 1-based, in brackets where the reader reports it).
  const std::map<std::string, std::pair<std::string, std::string>> edits = {
      {"t.node", {"1 1 0 0", "1 nan 0 0"}},
      {"t22.msh", {"2 1 0 0", "2 nan 0 0"}},
      {"t41.msh", {"\n1 0 0\n", "\nnan 0 0\n"}},
      {"classic.vtk", {"\n1 0 0", "\nnan 0 0"}},
      {"v51.vtk", {"0 0 0 1 0 0", "0 0 0 nan 0 0"}},
      {"t.off", {"\n1 0 0", "\nnan 0 0"}},
      {"t.obj", {"v 1 0 0", "v nan 0 0"}}};
  const std::map<std::string, std::string> where = {
      {"t.node", "t.node:3:"},    {"t22.msh", "t22.msh:7:"},
      {"t41.msh", "t41.msh:12:"}, {"classic.vtk", "classic.vtk:7:"},
      {"v51.vtk", "v51.vtk:6:"},  {"t.off", "t.off:4:"},
      {"t.obj", "(line 2)"}};
  for (const ReaderCase& c : ReaderCases()) {
    if (!edits.count(c.name)) continue;
    SCOPED_TRACE(c.name);
    const auto& [from, to] = edits.at(c.name);
    const std::string text = Replace(c.text, from, to);  // a lambda may not capture a binding
    ExpectInputError([&] { c.parse(text, c.name); }, {where.at(c.name), "'nan'", "finite"});
  }
}

TEST(BadInputTest, NodeIndicesOutOfRangeInEveryReaderAreNamed) {
  const std::map<std::string, std::tuple<std::string, std::string, std::string>> edits = {
      {"t.ele", {"0 0 1 2 3", "0 0 1 2 9", "t.ele:2: node index 9 is out of range [0, 3]"}},
      {"t22.msh", {"1 2 3 4\n", "1 2 3 9\n", "t22.msh:13: node tag 9 is not defined"}},
      {"t41.msh", {"1 1 2 3 4", "1 1 2 3 9", "t41.msh:19: node tag 9 is not defined"}},
      {"classic.vtk", {"4 0 1 2 3", "4 0 1 2 9", "classic.vtk:11: cell 0 refers to point 9"}},
      {"v51.vtk", {"\n0 1 2 3", "\n0 1 2 -1", "v51.vtk:12: cell 0 refers to point -1"}},
      {"t.off", {"3 1 2 3", "3 1 2 4", "t.off:10: vertex index 4 is out of range [0, 3]"}},
      {"t.obj", {"f 2 3 4", "f 2 3 5", "refers to vertex 4 but the file has 4 vertices (line 8)"}}};
  for (const ReaderCase& c : ReaderCases()) {
    if (!edits.count(c.name)) continue;
    SCOPED_TRACE(c.name);
    const auto& [from, to, message] = edits.at(c.name);
    const std::string text = Replace(c.text, from, to);  // a lambda may not capture a binding
    ExpectInputError([&] { c.parse(text, c.name); }, {message});
  }
}

TEST(BadInputTest, DegenerateTetInAFileIsNamed) {
  // Node 3 moved into the plane of nodes 0, 1, 2.
  ExpectInputError(
      [] {
        internal::ParseTetGenMesh(Replace(kTetGenNode, "3 0 0 1", "3 0.5 0.5 0"), "t.node",
                                  kTetGenEle, "t.ele");
      },
      {"t.ele: element 0 is degenerate"});
}

// ---- Surfaces for voxelization ----

// The outward-wound surface of the unit cube (1 x 1 x 1 cells: 8 vertices, 12 triangles).
SurfaceMesh UnitCubeSurface() {
  SurfaceMesh cube = MakeBoxSurface(Vec3(1, 1, 1), 1, 1, 1);
  cube.source = "cube.off";
  return cube;
}

// Expects VoxelizeSurface to reject the surface naming it and every part.
void ExpectBadSurface(const SurfaceMesh& surface, std::vector<std::string> parts) {
  parts.push_back("cube.off: ");
  ExpectInputError([&] { VoxelizeSurface(surface, 0.25); }, parts);
}

TEST(BadInputTest, OpenOrInconsistentSurfacesAreNotVoxelized) {
  SurfaceMesh open = UnitCubeSurface();
  open.triangles.pop_back();
  ExpectBadSurface(open, {"has no neighbouring triangle", "open"});
  SurfaceMesh flipped = UnitCubeSurface();
  std::swap(flipped.triangles[5][0], flipped.triangles[5][1]);
  ExpectBadSurface(flipped, {"inconsistently oriented"});
  ASSERT_NO_THROW(VoxelizeSurface(UnitCubeSurface(), 0.25));
}

TEST(BadInputTest, NonManifoldSurfaceIsNotVoxelized) {
  // Two unit cubes touching along the edge x = y = 1: that edge has four triangles.
  SurfaceMesh pair = UnitCubeSurface();
  const SurfaceMesh other = MakeBoxSurface(Vec3(1, 1, 1), 1, 1, 1, Vec3(1, 1, 0));
  std::map<std::array<double, 3>, int> index;
  for (int i = 0; i < static_cast<int>(pair.vertices.size()); ++i)
    index[{pair.vertices[i].x(), pair.vertices[i].y(), pair.vertices[i].z()}] = i;
  std::vector<int> map;
  for (const Vec3& v : other.vertices) {
    const auto [it, added] =
        index.emplace(std::array<double, 3>{v.x(), v.y(), v.z()}, pair.vertices.size());
    if (added) pair.vertices.push_back(v);
    map.push_back(it->second);
  }
  for (const Triangle& t : other.triangles)
    pair.triangles.push_back({map[t[0]], map[t[1]], map[t[2]]});
  ExpectBadSurface(pair, {"used in the same direction", "non-manifold"});
}

TEST(BadInputTest, DegenerateOrNonFiniteSurfacesAreNotVoxelized) {
  SurfaceMesh flat = UnitCubeSurface();
  const Triangle& t = flat.triangles[0];
  flat.vertices[t[2]] = 0.5 * (flat.vertices[t[0]] + flat.vertices[t[1]]);
  ExpectBadSurface(flat, {"is degenerate"});
  SurfaceMesh nan = UnitCubeSurface();
  nan.vertices[4].z() = kNan;
  ExpectBadSurface(nan, {"vertex 4 has a non-finite coordinate"});
  SurfaceMesh range = UnitCubeSurface();
  range.triangles[7][1] = 8;
  ExpectBadSurface(range, {"triangle 7 refers to vertex 8"});
}

// ---- Node indices, states and step arguments ----

TEST(BadInputTest, NodeIndicesOutOfRangeAreNamed) {
  auto body = MakeCube();
  ExpectInputError(
      [&] {
        body->FixNodes({3, 27});
      },
      {"body 'cube'", "FixNodes: node 27 out of range [0, 27)"});
  ExpectInputError([&] { body->FixNodes({-1}); }, {"node -1 out of range"});
  ExpectInputError([&] { body->SetKinematicTarget(40, Vec3::Zero()); }, {"node 40"});
  ExpectInputError([&] { body->ReleaseNode(-2); }, {"node -2"});
  ExpectInputError([&] { body->AddNodeForce(27, Vec3::Zero()); }, {"node 27"});
  ExpectInputError([&] { body->SetKinematicTarget(3, Vec3(0, kNan, 0)); },
                   {"kinematic target of node 3"});
  ExpectInputError([&] { body->AddNodeForce(3, Vec3(kInf, 0, 0)); }, {"force on node 3"});
}

TEST(BadInputTest, AttachingANodeOutOfRangeIsNamed) {
  BulletWorldHolder holder;
  btRigidBody* bone = holder.AddRigidBody(std::make_unique<btBoxShape>(btVector3(0.1, 0.1, 0.1)),
                                          0.0, btVector3(0, 0, 0));
  DeformableBodySettings settings;
  settings.name = "flesh";
  DeformableBody* flesh = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(1, 1, 1), 1, 1, 1, Vec3(-0.5, -0.5, -0.5)), settings);
  ExpectInputError(
      [&] {
        holder.world.AttachNodesToRigidBody(flesh, {0, 8}, bone);
      },
      {"body 'flesh'", "attached node 8 out of range [0, 8)"});
}

TEST(BadInputTest, NonFiniteOrMisSizedStatesAreRejected) {
  auto body = MakeCube();
  VecX x = body->x();
  x[40] = kNan;
  ExpectInputError([&] { body->set_x(x); }, {"body 'cube'", "non-finite position"});
  x[40] = kInf;
  ExpectInputError([&] { body->set_x(x); }, {"non-finite position"});
  ExpectInputError([&] { body->set_x(VecX::Zero(5)); }, {"set_x expects 81 values, got 5"});
  VecX v = VecX::Zero(81);
  v[7] = -kInf;
  ExpectInputError([&] { body->set_v(v); }, {"body 'cube'", "non-finite velocity"});
  ExpectInputError([&] { body->set_v(VecX::Zero(80)); }, {"set_v expects 81 values, got 80"});
}

// ---- Solver settings (ValidateSqpSettings at DeformableWorld::stepSimulation) ----

// A limited 0.2 m cube resting on the ground: every bad solver setting is rejected at the next
// stepSimulation naming its field, before anything moves, and the world steps on once the setting
// is set back.
TEST(BadInputTest, BadSolverSettingsAreNamedAndStepNothing) {
  BulletWorldHolder holder;
  holder.AddStaticGround();
  DeformableBodySettings body_settings;
  body_settings.name = "cube";
  DeformableBody* cube = holder.world.AddTetBody(
      MakeBoxTetMesh(Vec3(0.2, 0.2, 0.2), 2, 2, 2, Vec3(-0.1, -0.1, 0.001)), body_settings);
  holder.world.SetStrainLimits(cube, StrainLimitSettings::Isotropic(0.95, 1.05));
  const double h = 1.0 / 240.0;
  holder.world.stepSimulation(h, 1, h);
  const SqpSettings good = holder.world.solver_settings();
  using Edit = void (*)(SqpSettings&);
  const std::vector<std::pair<std::string, Edit>> cases = {
      {"SqpSettings::violation_tolerance = 0", [](SqpSettings& s) { s.violation_tolerance = 0.0; }},
      {"SqpSettings::contact_tolerance = nan", [](SqpSettings& s) { s.contact_tolerance = kNan; }},
      {"SqpSettings::stationarity_tolerance = -1",
       [](SqpSettings& s) { s.stationarity_tolerance = -1.0; }},
      {"SqpSettings::max_iterations = 0", [](SqpSettings& s) { s.max_iterations = 0; }},
      {"SqpSettings::stalled_step = 1", [](SqpSettings& s) { s.stalled_step = 1.0; }},
      {"SqpSettings::pgs: PgsSettings: relaxation = 2",
       [](SqpSettings& s) { s.pgs.relaxation = 2.0; }},
      {"SqpSettings::polish.max_rounds = -1", [](SqpSettings& s) { s.polish.max_rounds = -1; }},
      {"SqpSettings::solver = 7",
       [](SqpSettings& s) { s.solver = static_cast<IslandSolverKind>(7); }},
      {"SqpSettings::primal.penalty_scale = 0", [](SqpSettings& s) { s.primal.penalty_scale = 0; }},
      {"SqpSettings::primal.max_newton_iterations = 0",
       [](SqpSettings& s) { s.primal.max_newton_iterations = 0; }},
      {"SqpSettings::primal.penalty_growth = 0.5",
       [](SqpSettings& s) { s.primal.penalty_growth = 0.5; }},
      {"SqpSettings::primal.pcg_tolerance = inf",
       [](SqpSettings& s) { s.primal.pcg_tolerance = kInf; }},
      {"SqpSettings::retry_max_iterations = 0", [](SqpSettings& s) { s.retry_max_iterations = 0; }},
  };
  for (const auto& [message, edit] : cases) {
    const VecX x = cube->x(), v = cube->v();
    edit(holder.world.mutable_solver_settings());
    ExpectInputError([&] { holder.world.stepSimulation(h, 1, h); }, {message});
    EXPECT_EQ(cube->x(), x) << message;
    EXPECT_EQ(cube->v(), v) << message;
    holder.world.mutable_solver_settings() = good;
    holder.world.stepSimulation(h, 1, h);
    EXPECT_NE(cube->x(), x) << message << ": the world steps again once the setting is good";
  }
}

TEST(BadInputTest, StepArgumentsAreChecked) {
  auto body = MakeCube();
  for (double h : {0.0, -0.01, kNan, kInf})
    ExpectInputError([&] { body->BeginStep(h, Vec3(0, 0, -9.81)); }, {"body 'cube'", "time step"});
  ExpectInputError([&] { body->BeginStep(0.01, Vec3(0, kNan, 0)); }, {"body 'cube'", "gravity"});
}

}  // namespace
}  // namespace taut
