// Helpers shared by the mesh reader/writer tests: temp files, error checks, mesh comparison and a
// small mutation fuzzer.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "plugin/mesh_file_error.h"
#include "plugin/tet_mesh.h"

namespace taut::mesh_test {

// Removes this process's temp folder when the test binary exits.
struct TempRoot {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("taut_mesh_io_" + std::to_string(::getpid()));
  ~TempRoot() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

// A path in the temp directory unique to this process and test, ending in file_name.
inline std::string TempPath(const std::string& file_name) {
  static TempRoot root;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string test = info ? std::string(info->test_suite_name()) + "_" + info->name() : "x";
  const auto dir = root.path / test;
  std::filesystem::create_directories(dir);
  return (dir / file_name).string();
}

// Writes text to path (binary mode, so line endings stay as given).
inline void WriteTextFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

// A real as "%.17g", which reads back exactly.
inline std::string Real(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", x);
  return buffer;
}

// Expects read() to throw MeshFileError naming file and line (0 = no line) and containing reason.
template <typename Read>
void ExpectMeshFileError(Read&& read, const std::string& file, int line,
                         const std::string& reason) {
  try {
    read();
    ADD_FAILURE() << "no error; expected " << reason;
  } catch (const MeshFileError& e) {
    const std::string what = e.what();
    const std::string prefix = line > 0 ? file + ":" + std::to_string(line) + ": " : file + ": ";
    EXPECT_EQ(what.rfind(prefix, 0), 0u) << what << "\n  expected prefix: " << prefix;
    EXPECT_EQ(e.line(), line) << what;
    EXPECT_NE(what.find(reason), std::string::npos) << what << "\n  expected reason: " << reason;
  }
}

// Expects the same nodes (bit for bit) and the same tets.
inline void ExpectSameMesh(const TetMesh& expected, const TetMesh& actual) {
  ASSERT_EQ(expected.nodes.size(), actual.nodes.size());
  ASSERT_EQ(expected.tets.size(), actual.tets.size());
  for (std::size_t i = 0; i < expected.nodes.size(); ++i)
    EXPECT_EQ(expected.nodes[i], actual.nodes[i]) << "node " << i;
  for (std::size_t e = 0; e < expected.tets.size(); ++e)
    EXPECT_EQ(expected.tets[e], actual.tets[e]) << "tet " << e;
}

// Expects the 5-tet unit cube of tests/data: corners (i, j, k) numbered i + 2j + 4k, every tet
// positive, total volume 1.
inline void ExpectUnitCube(const TetMesh& mesh) {
  ASSERT_EQ(mesh.nodes.size(), 8u);
  ASSERT_EQ(mesh.tets.size(), 5u);
  for (int n = 0; n < 8; ++n) EXPECT_EQ(mesh.nodes[n], Vec3(n % 2, n / 2 % 2, n / 4)) << n;
  double volume = 0.0;
  for (const auto& t : mesh.tets) {
    const auto& X = mesh.nodes;
    const double v = CalcTetSignedVolume(X[t[0]], X[t[1]], X[t[2]], X[t[3]]);
    EXPECT_GT(v, 0.0);
    volume += v;
  }
  EXPECT_NEAR(volume, 1.0, 1e-15);
}

// Applies 1-4 random edits: byte flips, inserted or deleted spans, swapped numbers, duplicated or
// dropped lines, truncation.
inline std::string MutateText(std::string text, std::mt19937& rng) {
  static const char* kNumbers[] = {
      "-1",         "0",     "1",   "3",    "4",   "99999999999999999999",
      "2147483648", "1e999", "nan", "-inf", "1.5", "$EndNodes",
      "10",         "24",    "#"};
  auto pick = [&rng](std::size_t n) {
    return n ? std::uniform_int_distribution<std::size_t>(0, n - 1)(rng) : 0;
  };
  const int edits = 1 + static_cast<int>(pick(4));
  for (int e = 0; e < edits; ++e) {
    const std::size_t at = pick(text.size() + 1);
    switch (pick(6)) {
      case 0:
        if (!text.empty()) text[pick(text.size())] = static_cast<char>(pick(256));
        break;
      case 1:
        text.erase(at, pick(16));
        break;
      case 2:
        text.insert(at, 1 + pick(8), static_cast<char>(pick(256)));
        break;
      case 3: {  // replace the token at `at` with a nasty number
        std::size_t b = at, end = at;
        while (b > 0 && text[b - 1] > ' ') --b;
        while (end < text.size() && text[end] > ' ') ++end;
        text.replace(b, end - b, kNumbers[pick(sizeof(kNumbers) / sizeof(*kNumbers))]);
        break;
      }
      case 4: {  // duplicate or drop the line containing `at`
        const std::size_t b = text.rfind('\n', at == 0 ? 0 : at - 1);
        const std::size_t begin = b == std::string::npos ? 0 : b + 1;
        const std::size_t end = std::min(text.find('\n', begin), text.size());
        const std::string line = text.substr(begin, end - begin + 1);
        if (pick(2))
          text.insert(begin, line);
        else
          text.erase(begin, line.size());
        break;
      }
      default:
        text.resize(std::min(at, text.size()));
    }
  }
  return text;
}

// Random bytes, biased towards digits, blanks and newlines so some lines look numeric.
inline std::string RandomText(std::mt19937& rng, std::size_t max_size) {
  static const char kChars[] = "0123456789 \n\n-.e$#";
  std::string text(std::uniform_int_distribution<std::size_t>(0, max_size)(rng), '\0');
  for (char& c : text)
    c = rng() % 2 ? kChars[rng() % (sizeof(kChars) - 1)] : static_cast<char>(rng() % 256);
  return text;
}

// Counts of fuzz inputs that parsed and that were rejected with InputError.
struct FuzzCounts {
  int parsed = 0;
  int rejected = 0;
};

// Feeds parse() `count` inputs made from seed (mutations) and random bytes; every input must
// parse or throw InputError (anything else fails the test). The outcome of each is counted.
template <typename Parse>
FuzzCounts RunFuzz(const std::string& seed, int count, Parse&& parse) {
  std::mt19937 rng(12345);
  FuzzCounts counts;
  for (int i = 0; i < count; ++i) {
    const std::string text = i % 4 == 3 ? RandomText(rng, 400) : MutateText(seed, rng);
    try {
      parse(text);
      ++counts.parsed;
    } catch (const InputError&) {
      ++counts.rejected;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "input " << i << " threw a non-InputError: " << e.what();
    }
  }
  return counts;
}

}  // namespace taut::mesh_test
