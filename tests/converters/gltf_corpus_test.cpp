// The reader against outside corpora: the Khronos glTF-Validator's test assets (mostly broken on
// purpose) and Debian's assimp-testmodels. Every file converts or fails with one line naming it;
// where the validator finds no error in a file with meshes, we must convert it.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "converters/gltf_json.h"
#include "converters/gltf_read.h"
#include "converters/point_io.h"
#include "test_support.h"

namespace dpoint {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

const std::string kValidatorDir = std::string(DPOINT_CORPUS_DIR) + "/gltf-validator";
const std::string kAssimpDir = "/usr/share/assimp/models/glTF2";

std::vector<std::string> modelFiles(const std::string& root) {
  std::vector<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".gltf" || ext == ".glb")) files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Validator files with no errors and mesh data that we still refuse, and why.
const std::map<std::string, std::string> kExpectedRefusals = {
    // tinygltf 2.7.0 requires a uri on every buffer of a .gltf; the spec allows an unused one without.
    {"base/data/json/integer_written_as_float.gltf", "tinygltf: buffer without uri in .gltf"},
    {"base/data/root/named_objects.gltf", "tinygltf: buffer without uri in .gltf"},
    {"base/data/root/unused_objects.gltf", "tinygltf: buffer without uri in .gltf"},
    // tinygltf 2.7.0 refuses an accessor without bufferView that is not sparse ("invalid bufferView").
    {"base/data/mesh/valid.gltf", "tinygltf: accessor without bufferView"},
};

struct Verdict {
  bool known = false;
  int errors = 0;
};

Verdict validatorVerdict(const std::string& file) {
  Verdict v;
  const std::string report = file + ".report.json";
  if (!test::fileExists(report)) return v;
  Result<JsonValue> json = parseJson(test::readFile(report), 64);
  if (!json) return v;
  const JsonValue* issues = json->find("issues");
  const JsonValue* errors = issues ? issues->find("numErrors") : nullptr;
  if (!errors || !errors->is_integer) return v;
  v.known = true;
  v.errors = int(errors->integer);
  return v;
}

// Whether the file's JSON lists a non-empty meshes array (GLB: its JSON chunk is searched as text).
bool hasMeshes(const std::string& file) {
  const std::string bytes = test::readFile(file);
  const size_t at = bytes.find("\"meshes\"");
  if (at == std::string::npos) return false;
  const size_t open = bytes.find_first_not_of(" \t\r\n:", at + 8);
  return open != std::string::npos && bytes[open] == '[' &&
         bytes.find_first_not_of(" \t\r\n", open + 1) != std::string::npos &&
         bytes[bytes.find_first_not_of(" \t\r\n", open + 1)] != ']';
}

TEST(GltfCorpus, validatorAssetsConvertOrFailOnOneLine) {
  ASSERT_TRUE(fs::is_directory(kValidatorDir)) << kValidatorDir << " is absent: the shared corpus must sit beside the checkout";
  TempDir dir;
  int converted = 0, empty = 0, rejected = 0, agree = 0, disagree = 0;
  std::vector<std::string> disagreements;
  const std::vector<std::string> files = modelFiles(kValidatorDir);
  EXPECT_GE(files.size(), 372u);
  for (const std::string& file : files) {
    Result<PointSet> set = readGltf(file);
    const Verdict verdict = validatorVerdict(file);
    if (set) {
      if (set->positions.empty()) {
        ++empty;
      } else {
        Status written = writePoints(dir.file("out.csv"), *set);
        EXPECT_TRUE(written) << file << ": " << written.error().message;
        ++converted;
      }
    } else {
      ++rejected;
      const std::string& message = set.error().message;
      EXPECT_EQ(message.rfind(file + ": ", 0), 0u) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
    if (!verdict.known) continue;
    // Agreement: we accept what the validator finds valid, and refuse what it finds broken.
    // Refusing a broken file is not required (many errors are in parts we never read).
    if (verdict.errors == 0 && !set && hasMeshes(file)) {
      const std::string name = fs::relative(file, kValidatorDir).string();
      if (!kExpectedRefusals.count(name)) {
        ADD_FAILURE() << "validator finds no error, we refuse: " << set.error().message;
      }
      ++disagree;
      disagreements.push_back(name + " (valid, refused: " + set.error().message + ")");
    } else if ((verdict.errors == 0) == bool(set)) {
      ++agree;
    } else {
      ++disagree;
      disagreements.push_back(fs::relative(file, kValidatorDir).string() + (set ? " (errors, converted)" : " (valid, refused: " + set.error().message + ")"));
    }
  }
  std::cout << "gltf-validator corpus: " << files.size() << " files, " << converted << " converted, " << empty
            << " read with no points, " << rejected << " rejected; validator verdict agrees " << agree
            << ", differs " << disagree << "\n";
  for (const std::string& d : disagreements) std::cout << "  differs: " << d << "\n";
  RecordProperty("converted", converted);
  RecordProperty("empty", empty);
  RecordProperty("rejected", rejected);
  RecordProperty("agree", agree);
  RecordProperty("disagree", disagree);
}

// The same through the binary, for the first five files the library refuses: exit 2 and one
// line on stderr naming the file.
TEST(GltfCorpus, binaryExitsTwoOnBrokenValidatorAssets) {
  ASSERT_TRUE(fs::is_directory(kValidatorDir)) << kValidatorDir << " is absent: the shared corpus must sit beside the checkout";
  TempDir dir;
  int checked = 0;
  for (const std::string& file : modelFiles(kValidatorDir)) {
    if (checked == 5) break;
    if (readGltf(file)) continue;
    test::CommandResult r = test::runDpoint({"convert", file, "-o", dir.file("out.csv")});
    EXPECT_EQ(r.exit_code, 2) << file << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(file + ": "), std::string::npos) << r.err;
    ++checked;
  }
  EXPECT_EQ(checked, 5);
}

TEST(GltfCorpus, assimpPrimitiveModesGiveTheirPointCounts) {
  const std::string dir = kAssimpDir + "/glTF-Asset-Generator/Mesh_PrimitiveMode/";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << " is absent (scripts/setup installs assimp-testmodels)";
  // Modes 0-6 without indices, then with: points (1024), lines (8 vertices, shared ones repeated),
  // loop (4), strip (5), triangle strip/fan (4), triangles (6); indexed: the 4 referenced vertices.
  const size_t points[16] = {1024, 8, 4, 5, 4, 4, 6, 1024, 4, 4, 4, 4, 4, 4, 4, 4};
  const size_t triangles[16] = {0, 0, 0, 0, 2, 2, 2, 0, 0, 0, 0, 2, 2, 2, 2, 2};
  for (int i = 0; i < 16; ++i) {
    const std::string file = dir + "Mesh_PrimitiveMode_" + (i < 10 ? "0" : "") + std::to_string(i) + ".gltf";
    Result<PointSet> set = readGltf(file);
    ASSERT_TRUE(set) << set.error().message;
    EXPECT_EQ(set->size(), points[i]) << file;
    EXPECT_EQ(set->triangles.size(), 3 * triangles[i]) << file;
  }
}

TEST(GltfCorpus, assimpBrokenModelsAreRefusedAndGoodOnesConvert) {
  ASSERT_TRUE(fs::is_directory(kAssimpDir)) << kAssimpDir << " is absent (scripts/setup installs assimp-testmodels)";
  const auto refused = [](const std::string& file, const std::string& part) {
    Result<PointSet> set = readGltf(kAssimpDir + "/" + file);
    ASSERT_FALSE(set) << file;
    EXPECT_NE(set.error().message.find(part), std::string::npos) << set.error().message;
  };
  refused("RecursiveNodes/RecursiveNodes.gltf", "cycle");
  refused("IndexOutOfRange/IndexOutOfRange.gltf", "out of range");
  refused("BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "is not finite");
  Result<PointSet> engine = readGltf(kAssimpDir + "/2CylinderEngine-glTF-Binary/2CylinderEngine.glb");
  ASSERT_TRUE(engine) << engine.error().message;
  EXPECT_GT(engine->size(), 0u);
  // The same model Draco-compressed: Draco splits vertices at attribute seams, so there are a few
  // more points (84,716 against 84,657; tests/external compares them point by point).
  Result<PointSet> draco = readGltf(kAssimpDir + "/draco/2CylinderEngine.gltf");
  ASSERT_TRUE(draco) << draco.error().message;
  EXPECT_EQ(draco->size(), 84716u);
  EXPECT_EQ(engine->size(), 84657u);
  // glTF 1.0 files are refused, not read as empty models.
  const std::string v1 = "/usr/share/assimp/models/glTF";
  for (const std::string& file : modelFiles(v1)) {
    Result<PointSet> set = readGltf(file);
    EXPECT_FALSE(set) << file;
  }
  TempDir dir;
  test::CommandResult r = test::runDpoint({"convert", kAssimpDir + "/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
                                           "-o", dir.file("never.csv")});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(dir.entries().empty()) << "nothing written";
  // A valid file whose scene places no mesh: an empty set, so a CSV with its header only (issue #24).
  const std::string no_scene = kAssimpDir + "/TestNoRootNode/NoScene.gltf";
  r = test::runDpoint({"convert", no_scene, "-o", dir.file("out.csv")});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(test::readFile(dir.file("out.csv")), "x,y,z\n");
}

// Every glTF file assimp ships converts or fails on one line, with no crash.
TEST(GltfCorpus, assimpModelsConvertOrFailOnOneLine) {
  ASSERT_TRUE(fs::is_directory(kAssimpDir)) << kAssimpDir << " is absent (scripts/setup installs assimp-testmodels)";
  int converted = 0, rejected = 0;
  for (const std::string& file : modelFiles(kAssimpDir)) {
    Result<PointSet> set = readGltf(file);
    if (set) {
      ++converted;
      continue;
    }
    ++rejected;
    EXPECT_EQ(set.error().message.rfind(file + ": ", 0), 0u) << set.error().message;
    EXPECT_EQ(set.error().message.find('\n'), std::string::npos) << set.error().message;
    std::cout << "  assimp refused: " << set.error().message << "\n";
  }
  std::cout << "assimp glTF2 models: " << converted << " converted, " << rejected << " rejected\n";
}

}  // namespace
}  // namespace dpoint
