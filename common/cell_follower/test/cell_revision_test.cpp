// read_revision: a revision's document read as a reader of the cell file would, against its own cell file.
#include "rigger/cell_follower/cell_revision.hpp"

#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

namespace rigger::cell_follower {
namespace {

namespace fs = std::filesystem;

const fs::path kShippedCell = fs::path(RIGGER_SOURCE_DIR) / "deploy/cell/simulated_cell.json";

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

world_protocol::CellRevision revision_of(std::string document, std::uint64_t number = 2) {
  world_protocol::CellRevision r;
  r.cell_revision = number;
  r.previous_revision = number - 1;
  r.cell_json = std::move(document);
  r.sha256 = "00";
  r.changes_json = R"({"added":[],"removed":[],"moved":[{"id":"load","distance_m":0.1,"angle_deg":0}],"changed":[]})";
  r.who = "ada";
  r.comment = "moved the load";
  return r;
}

TEST(CellRevision, TheShippedCellIsTakenWithModelsResolvedAgainstTheReadersFolder) {
  const RevisionReading got = read_revision(revision_of(read_text(kShippedCell)), kShippedCell);
  ASSERT_TRUE(got.revision.has_value()) << got.refusal;
  EXPECT_EQ(got.revision->revision, 2U);
  EXPECT_EQ(got.revision->previous_revision, 1U);
  EXPECT_EQ(got.revision->model_dir, kShippedCell.parent_path());
  EXPECT_EQ(got.revision->cell.source, kShippedCell.string());
  EXPECT_NE(got.revision->cell.find("load"), nullptr);
  EXPECT_EQ(got.revision->changes["moved"][0]["id"], "load");
  EXPECT_EQ(got.revision->who, "ada");
  EXPECT_EQ(got.revision->comment, "moved the load");
}

TEST(CellRevision, AModelTheReadersFolderLacksIsRefusedWithItsPath) {
  // The same document, but this reader's cell file sits in a folder without the models.
  const fs::path elsewhere = fs::temp_directory_path() / "rigger_cell_revision_test" / "cell.json";
  const RevisionReading got = read_revision(revision_of(read_text(kShippedCell)), elsewhere);
  ASSERT_FALSE(got.revision.has_value());
  EXPECT_NE(got.refusal.find("cell revision 2: "), std::string::npos) << got.refusal;
  EXPECT_NE(got.refusal.find(elsewhere.string() + ": /entities/"), std::string::npos) << got.refusal;
  EXPECT_NE(got.refusal.find("/model/step"), std::string::npos) << got.refusal;
  EXPECT_NE(got.refusal.find((elsewhere.parent_path() / "models").string()), std::string::npos) << got.refusal;
}

TEST(CellRevision, MalformedJsonIsRefusedNamingTheReadersFile) {
  const RevisionReading got = read_revision(revision_of("{\"cell_version\": 1,"), kShippedCell);
  ASSERT_FALSE(got.revision.has_value());
  EXPECT_EQ(got.refusal.rfind("cell revision 2: " + kShippedCell.string() + ": ", 0), 0U) << got.refusal;
  EXPECT_NE(got.refusal.find("valid JSON"), std::string::npos) << got.refusal;
}

TEST(CellRevision, AnInvalidCellIsRefusedWithTheJsonPointer) {
  nlohmann::json cell = nlohmann::json::parse(read_text(kShippedCell));
  std::string pointer;
  for (std::size_t i = 0; i < cell["entities"].size(); ++i) {
    auto& e = cell["entities"][i];
    if (e["id"] == "load") {
      e["model"]["mass_kg"] = -1.0;
      pointer = "/entities/" + std::to_string(i) + "/model/mass_kg";
    }
  }
  ASSERT_FALSE(pointer.empty());
  const RevisionReading got = read_revision(revision_of(cell.dump()), kShippedCell);
  ASSERT_FALSE(got.revision.has_value());
  EXPECT_NE(got.refusal.find(pointer), std::string::npos) << got.refusal;
}

TEST(CellRevision, RevisionZeroAndMalformedChangesAreRefused) {
  EXPECT_FALSE(read_revision(revision_of(read_text(kShippedCell), 0), kShippedCell).revision.has_value());
  world_protocol::CellRevision r = revision_of(read_text(kShippedCell));
  r.changes_json = "[1,2]";
  const RevisionReading got = read_revision(r, kShippedCell);
  ASSERT_FALSE(got.revision.has_value());
  EXPECT_NE(got.refusal.find("changes_json"), std::string::npos) << got.refusal;
}

}  // namespace
}  // namespace rigger::cell_follower
