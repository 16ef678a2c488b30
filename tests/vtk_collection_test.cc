// ParaView collections (.pvd) of --vtk runs: the writer, and a tiny scene run for a few frames
// whose every <body>.pvd lists existing files at increasing times.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "demos/scenes/scene.h"
#include "plugin/vtk_collection_writer.h"

namespace taut {
namespace {

namespace fs = std::filesystem;

// A DataSet of a parsed .pvd.
struct ParsedDataSet {
  double timestep;
  std::string file;
};

// The DataSet elements of a .pvd file (timestep and file attributes, XML entities undone), or
// fails the test when the file is not a VTK collection.
std::vector<ParsedDataSet> ParsePvd(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string xml = text.str();
  EXPECT_NE(xml.find("<VTKFile type=\"Collection\""), std::string::npos) << path;
  EXPECT_NE(xml.find("</Collection>"), std::string::npos) << path;
  std::vector<ParsedDataSet> sets;
  const std::regex dataset(R"re(<DataSet\s+timestep="([^"]*)"[^>]*\sfile="([^"]*)"\s*/>)re");
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), dataset);
       it != std::sregex_iterator(); ++it) {
    std::string file = (*it)[2];
    for (const auto& [entity, c] : {std::pair{"&lt;", "<"},
                                    {"&gt;", ">"},
                                    {"&quot;", "\""},
                                    {"&apos;", "'"},
                                    {"&amp;", "&"}}) {
      for (size_t at = file.find(entity); at != std::string::npos; at = file.find(entity, at + 1))
        file.replace(at, std::string(entity).size(), c);
    }
    sets.push_back({std::stod((*it)[1]), file});
  }
  return sets;
}

// A fresh empty folder under the test temp dir.
fs::path MakeFreshDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(VtkCollectionTest, WritesEveryEntryInOrderWithEscapedNames) {
  const fs::path dir = MakeFreshDir("vtk_collection_writer");
  const std::vector<VtkCollectionEntry> entries = {
      {0.0, "a_000000.vtk"}, {1.0 / 240.0, "a&b <1>_000001.vtk"}, {0.5, "a_000002.vtk"}};
  WriteVtkCollection((dir / "a.pvd").string(), entries);
  const std::vector<ParsedDataSet> sets = ParsePvd(dir / "a.pvd");
  ASSERT_EQ(sets.size(), entries.size());
  for (size_t i = 0; i < sets.size(); ++i) {
    EXPECT_EQ(sets[i].file, entries[i].file);
    EXPECT_EQ(sets[i].timestep, entries[i].time);  // 17 digits read back exactly
  }
  EXPECT_FALSE(fs::exists(dir / "a.pvd.tmp"));
  EXPECT_THROW(WriteVtkCollection((dir / "no_such_dir" / "a.pvd").string(), entries), InputError);
}

TEST(VtkCollectionTest, SeriesWriterRewritesOnEveryAddAndUpdatesARepeatedLastFile) {
  const fs::path dir = MakeFreshDir("vtk_series_writer");
  VtkSeriesWriter writer;
  writer.Add(dir.string(), "body", "body_000000.vtk", 0.0);
  EXPECT_EQ(ParsePvd(dir / "body.pvd").size(), 1u);
  writer.Add(dir.string(), "body", "body_000001.vtk", 0.1);
  writer.Add(dir.string(), "body", "body_000001.vtk", 0.2);  // same frame again: time updated
  writer.Add(dir.string(), "other", "other_000000.vtk", 0.0);
  const std::vector<ParsedDataSet> sets = ParsePvd(dir / "body.pvd");
  ASSERT_EQ(sets.size(), 2u);
  EXPECT_EQ(sets[1].file, "body_000001.vtk");
  EXPECT_EQ(sets[1].timestep, 0.2);
  EXPECT_EQ(writer.entries(dir.string(), "other").size(), 1u);
  EXPECT_TRUE(writer.entries(dir.string(), "none").empty());
}

// A tiny scene (falling_sphere: three 32-hex spheres) for 4 frames, as taut-demo --vtk writes them:
// one .pvd per body, each DataSet's file present next to it, timesteps the frames' times.
TEST(VtkCollectionTest, SceneRunWritesOnePvdPerBodyListingEveryFrame) {
  const fs::path dir = MakeFreshDir("vtk_collection_scene");
  const SceneInfo& info = FindScene("falling_sphere");
  std::unique_ptr<Scene> scene = info.make();
  const double dt = info.default_dt;
  constexpr int kSteps = 3;
  scene->WriteVtkFrame(dir.string(), 0, 0.0);
  for (int step = 1; step <= kSteps; ++step) {
    scene->Step(dt);
    scene->WriteVtkFrame(dir.string(), step, step * dt);
  }
  int collections = 0;
  for (int b = 0; b < scene->world().num_deformable_bodies(); ++b) {
    const fs::path pvd = dir / (scene->world().deformable_body(b).name() + ".pvd");
    ASSERT_TRUE(fs::exists(pvd)) << pvd;
    ++collections;
    const std::vector<ParsedDataSet> sets = ParsePvd(pvd);
    ASSERT_EQ(sets.size(), static_cast<size_t>(kSteps + 1)) << pvd;
    for (size_t i = 0; i < sets.size(); ++i) {
      EXPECT_TRUE(fs::exists(dir / sets[i].file)) << sets[i].file;
      EXPECT_NEAR(sets[i].timestep, static_cast<double>(i) * dt, 1e-15);
      if (i > 0) EXPECT_GT(sets[i].timestep, sets[i - 1].timestep) << pvd;
    }
  }
  EXPECT_EQ(collections, 3);
}

}  // namespace
}  // namespace taut
