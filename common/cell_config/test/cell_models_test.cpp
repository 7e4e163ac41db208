// Where a revision's STEP models are read from (cell_models.hpp): the cell folder, or, for a pinned model
// whose bytes the folder lacks, the store of uploaded or received models, through a folder of links.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rigger/base/sha256.hpp"
#include "rigger/cell_config/cell_models.hpp"

namespace rigger::cell {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

class CellModelsTest : public ::testing::Test {
 protected:
  CellModelsTest() {
    root_ = fs::temp_directory_path() / ("rigger-cell-models-test-" + std::to_string(::getpid()) + "-" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    write(root_ / "cell/models/load.step", "the load's bytes");
    write(root_ / "cell/models/target.step", "the target's bytes");
    std::ifstream shipped(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json");
    doc_ = json::parse(shipped);
    // Only the two objects whose models this folder has.
    json kept = json::array();
    for (const json& e : doc_["entities"])
      if (e["id"] != "part" && e["id"] != "part_fixture") kept.push_back(e);
    doc_["entities"] = kept;
  }
  ~CellModelsTest() override { fs::remove_all(root_); }

  CellFile cell_with_load_pinned(const std::string& sha256) {
    json doc = doc_;
    for (json& e : doc["entities"])
      if (e["id"] == "load") e["model"]["sha256"] = sha256;
    return cell_file_from_json(doc, (root_ / "cell/cell.json").string());
  }

  fs::path root_;
  json doc_;
};

TEST_F(CellModelsTest, UnpinnedAndMatchingModelsAreReadFromTheCellFolderItself) {
  const ModelStore store(root_ / "store");
  const ModelFolder unpinned =
      resolve_models(cell_file_from_json(doc_, (root_ / "cell/cell.json").string()), root_ / "cell", store, root_ / "links");
  EXPECT_EQ(unpinned.dir, root_ / "cell");
  EXPECT_TRUE(unpinned.missing.empty());
  const ModelFolder pinned =
      resolve_models(cell_with_load_pinned(sha256_hex("the load's bytes")), root_ / "cell", store, root_ / "links");
  EXPECT_EQ(pinned.dir, root_ / "cell");
  EXPECT_TRUE(pinned.missing.empty());
  EXPECT_FALSE(fs::exists(root_ / "links")) << "no links are made when the folder has everything";
}

TEST_F(CellModelsTest, APinnedModelTheFolderLacksIsNamedUntilTheStoreHasIt) {
  ModelStore store(root_ / "store");
  const std::string uploaded = "the uploaded load's bytes";
  const CellFile cell = cell_with_load_pinned(sha256_hex(uploaded));
  const ModelFolder before = resolve_models(cell, root_ / "cell", store, root_ / "links");
  ASSERT_EQ(before.missing.size(), 1U);
  EXPECT_EQ(before.missing[0].pointer, "/entities/5/model");
  EXPECT_EQ(before.missing[0].name, "models/load.step");
  EXPECT_EQ(before.missing[0].sha256, sha256_hex(uploaded));

  EXPECT_EQ(store.put(uploaded), sha256_hex(uploaded));
  EXPECT_EQ(store.put(uploaded), sha256_hex(uploaded)) << "a second put of the same bytes is the same model";
  const ModelFolder after = resolve_models(cell, root_ / "cell", store, root_ / "links");
  EXPECT_TRUE(after.missing.empty());
  EXPECT_NE(after.dir, root_ / "cell");
  // The pinned name reads the stored bytes, not the folder's other bytes under that name; the unpinned
  // model reads the folder's.
  EXPECT_EQ(read(after.dir / "models/load.step"), uploaded);
  EXPECT_EQ(read(after.dir / "models/target.step"), "the target's bytes");
  EXPECT_EQ(resolve_models(cell, root_ / "cell", store, root_ / "links").dir, after.dir)
      << "the same revision reuses its folder";
}

TEST_F(CellModelsTest, AnUploadedModelsNameMustStayInsideTheCellFolderAndBeAStepFile) {
  EXPECT_EQ(model_name_problem("imported/bracket.STEP"), "");
  EXPECT_EQ(model_name_problem("plate.stp"), "");
  EXPECT_NE(model_name_problem(""), "");
  EXPECT_NE(model_name_problem("../outside.step").find("inside the cell folder"), std::string::npos);
  EXPECT_NE(model_name_problem("a/../../b.step").find("inside the cell folder"), std::string::npos);
  EXPECT_NE(model_name_problem("/etc/passwd.step").find("inside the cell folder"), std::string::npos);
  EXPECT_NE(model_name_problem("notes.txt").find(".step or .stp"), std::string::npos);
  EXPECT_NE(model_name_problem(std::string(300, 'a') + ".step").find("at most 255"), std::string::npos);
}

TEST_F(CellModelsTest, TheStoreFindsOnlyWhatItHolds) {
  ModelStore store(root_ / "store");
  EXPECT_TRUE(store.find(sha256_hex("nothing")).empty());
  EXPECT_TRUE(store.find("../../etc/passwd").empty()) << "only a sha256 names a stored model";
  const std::string sha = store.put("bytes");
  EXPECT_EQ(read(store.find(sha)), "bytes");
  EXPECT_EQ(file_sha256(store.find(sha)), sha);
  EXPECT_EQ(file_sha256(root_ / "no such file"), "");
}

}  // namespace
}  // namespace rigger::cell
