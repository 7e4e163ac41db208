// The document the rehearsal cell starts on: the revision's bytes in cell.json, each model path a link to
// the right bytes — from the rehearsal cell's own cell folder when unpinned, from the models sent with the
// revision when pinned — and a clear error for a model found nowhere.
#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rehearsal_cell_file.hpp"
#include "rigger/base/sha256.hpp"

namespace rigger::console {
namespace {

namespace fs = std::filesystem;

std::string bytes_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class RehearsalCellFilesTest : public ::testing::Test {
 protected:
  RehearsalCellFilesTest()
      : folder_(fs::path(RIGGER_SOURCE_DIR) / "deploy/cell"),
        root_(::testing::TempDir() + "/rehearsal-cells-" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name()),
        shipped_(bytes_of(folder_ / "simulated_cell.json")) {
    fs::remove_all(root_);
  }
  /// The shipped cell with its load's model replaced by `step`, pinned to `sha256`.
  CellTarget new_load(const std::string& sha256) const {
    nlohmann::json doc = nlohmann::json::parse(shipped_);
    for (auto& e : doc["entities"])
      if (e["id"] == "load") e["model"].update({{"step", "models/bracket.step"}, {"sha256", sha256}});
    const std::string text = doc.dump(2);
    return {4, sha256_hex(text), text, {}};
  }

  fs::path folder_;
  fs::path root_;
  std::string shipped_;
};

TEST_F(RehearsalCellFilesTest, TheShippedDocumentReadsItsModelsFromTheCellFolder) {
  const fs::path file = [&] {
    RehearsalCellFiles files(folder_, root_);
    const fs::path written = files.write({1, sha256_hex(shipped_), shipped_, {}});
    EXPECT_TRUE(written.is_absolute());
    EXPECT_EQ(bytes_of(written), shipped_) << "byte for byte: the world model's first revision is this file";
    EXPECT_EQ(fs::canonical(written.parent_path() / "models/load.step"), fs::canonical(folder_ / "models/load.step"));
    EXPECT_EQ(files.write({1, sha256_hex(shipped_), shipped_, {}}), written) << "written once per revision";
    return written;
  }();
  EXPECT_FALSE(fs::exists(file)) << "removed with its owner";
}

TEST_F(RehearsalCellFilesTest, APinnedModelIsTheBytesSentWithTheRevision) {
  const std::string step = "ISO-10303-21;\nthe bracket's bytes\n";
  CellTarget target = new_load(sha256_hex(step));
  target.models.push_back({sha256_hex(step), "models/bracket.step", step});
  RehearsalCellFiles files(folder_, root_);
  const fs::path written = files.write(target);
  EXPECT_EQ(bytes_of(written.parent_path() / "models/bracket.step"), step);
  EXPECT_EQ(fs::canonical(written.parent_path() / "models/target.step"), fs::canonical(folder_ / "models/target.step"));
}

TEST_F(RehearsalCellFilesTest, AModelFoundNowhereIsSaidWithItsPointer) {
  const std::string step = "ISO-10303-21;\nthe bracket's bytes\n";
  CellTarget target = new_load(sha256_hex(step));
  target.models.push_back({sha256_hex(step), "models/bracket.step", "other bytes"});
  RehearsalCellFiles files(folder_, root_);
  try {
    files.write(target);
    FAIL() << "a pinned model nobody sent was written";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("the cell's revision 4 at /entities/"), std::string::npos) << what;
    EXPECT_NE(what.find("/model: the model models/bracket.step (sha256 " + sha256_hex(step) + ")"), std::string::npos)
        << what;
  }
  RehearsalCellFiles no_folder("", root_ / "no-folder");
  try {
    no_folder.write({1, sha256_hex(shipped_), shipped_, {}});
    FAIL() << "unpinned models without a cell folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("rehearsal/cell_folder is not configured"), std::string::npos) << e.what();
  }
  EXPECT_THROW(files.write({0, "", "", {}}), std::runtime_error) << "no revision known";
}

}  // namespace
}  // namespace rigger::console
