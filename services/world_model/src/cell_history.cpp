#include "cell_history.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "rigger/base/bounded_json.hpp"
#include "world_json.hpp"

namespace rigger::world {
namespace {

namespace fs = std::filesystem;

constexpr const char* kPrefix = "revision-";
constexpr const char* kSuffix = ".json";

fs::path file_of(const fs::path& folder, std::uint64_t revision) {
  char name[40];
  std::snprintf(name, sizeof name, "%s%010llu%s", kPrefix, static_cast<unsigned long long>(revision), kSuffix);
  return folder / name;
}

// Writes, flushes to the disk and renames into place: a reader sees the old file or the whole new one.
std::string write_atomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return "cannot create " + tmp.string();
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n <= 0) {
      ::close(fd);
      fs::remove(tmp);
      return "cannot write " + tmp.string();
    }
    written += static_cast<std::size_t>(n);
  }
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  std::error_code ec;
  if (!synced) {
    fs::remove(tmp, ec);
    return "cannot flush " + tmp.string();
  }
  fs::rename(tmp, path, ec);
  if (ec) return "cannot rename " + tmp.string() + " to " + path.string() + ": " + ec.message();
  const int dir = ::open(path.parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
  return {};
}

}  // namespace

nlohmann::json to_json(const CellRevisionRecord& r) {
  return {{"cell_revision", r.revision},  {"previous_revision", r.previous_revision},
          {"sha256", r.sha256},           {"cell_file", r.cell_file},
          {"file_sha256", r.file_sha256}, {"who", r.who},
          {"comment", r.comment},         {"stamp_ns", to_unix_ns(r.stamp)},
          {"changes", r.changes},         {"cell_json", r.cell_json}};
}

CellRevisionRecord record_from_json(const nlohmann::json& j) {
  CellRevisionRecord r;
  r.revision = j.at("cell_revision").get<std::uint64_t>();
  r.previous_revision = j.at("previous_revision").get<std::uint64_t>();
  r.sha256 = j.at("sha256").get<std::string>();
  r.cell_file = j.at("cell_file").get<std::string>();
  r.file_sha256 = j.at("file_sha256").get<std::string>();
  r.who = j.at("who").get<std::string>();
  r.comment = j.at("comment").get<std::string>();
  r.stamp = from_unix_ns(j.at("stamp_ns").get<std::int64_t>());
  r.changes = j.at("changes");
  r.cell_json = j.at("cell_json").get<std::string>();
  return r;
}

CellHistory::CellHistory(fs::path folder, std::size_t max_revisions)
    : folder_(std::move(folder)), max_revisions_(std::max<std::size_t>(1, max_revisions)) {
  if (folder_.empty()) return;
  std::error_code ec;
  fs::create_directories(folder_, ec);
  if (ec) throw CellHistoryError(folder_.string() + ": cannot create the cell history folder: " + ec.message());
  for (fs::directory_iterator it(folder_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(kPrefix, 0) != 0 || name.size() <= std::string(kSuffix).size() ||
        name.compare(name.size() - 5, 5, kSuffix) != 0)
      continue;  // a leftover .tmp of an interrupted write, or someone else's file
    JsonParseResult parsed = parse_json_file_bounded(it->path(), {64U * 1024U * 1024U, 64});
    if (!parsed.ok()) throw CellHistoryError(it->path().string() + ": " + parsed.error->to_string());
    try {
      revisions_.push_back(record_from_json(parsed.value));
    } catch (const nlohmann::json::exception& e) {
      throw CellHistoryError(it->path().string() + ": expected a cell revision record: " + e.what());
    }
  }
  if (ec) throw CellHistoryError(folder_.string() + ": cannot read the cell history folder: " + ec.message());
  std::sort(revisions_.begin(), revisions_.end(),
            [](const CellRevisionRecord& a, const CellRevisionRecord& b) { return a.revision < b.revision; });
}

const CellRevisionRecord* CellHistory::find(std::uint64_t revision) const {
  for (const CellRevisionRecord& r : revisions_)
    if (r.revision == revision) return &r;
  return nullptr;
}

const CellRevisionRecord* CellHistory::latest_of(const std::string& cell_file) const {
  for (auto it = revisions_.rbegin(); it != revisions_.rend(); ++it)
    if (it->cell_file == cell_file) return &*it;
  return nullptr;
}

std::uint64_t CellHistory::next_revision() const {
  return revisions_.empty() ? 1 : revisions_.back().revision + 1;
}

std::string CellHistory::append(CellRevisionRecord record) {
  if (!folder_.empty()) {
    const std::string error = write_atomically(file_of(folder_, record.revision), to_json(record).dump(1));
    if (!error.empty()) return error;
  }
  revisions_.push_back(std::move(record));
  while (revisions_.size() > max_revisions_) {
    if (!folder_.empty()) {
      std::error_code ec;
      fs::remove(file_of(folder_, revisions_.front().revision), ec);
    }
    revisions_.erase(revisions_.begin());
  }
  return {};
}

}  // namespace rigger::world
