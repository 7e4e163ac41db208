#include "stage_trace.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace rigger::task_controller {
namespace {

std::int64_t ns_of(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

std::int64_t wall_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

StageTrace::StageTrace(std::size_t capacity) : capacity_(capacity) {
  records_.reserve(capacity);
}

void StageTrace::mark(const char* what, char phase) {
  if (marks_.size() < capacity_) marks_.push_back({ns_of(Clock::now()), what, phase});
}

void StageTrace::mark_at(std::int64_t ns, const char* what, char phase) {
  if (marks_.size() < capacity_) marks_.push_back({ns, what, phase});
}

void StageTrace::woke() {
  woke_ns_ = ns_of(Clock::now());
  woke_wall_ns_ = wall_ns();
}

void StageTrace::begin(const std::string& executor_id, const std::string& kind, std::int64_t stamp_wall_ns) {
  open_ = records_.size() < capacity_;
  if (!open_) return;
  records_.push_back({executor_id, kind, stamp_wall_ns, woke_wall_ns_, woke_ns_, 0, 0, 0, 0});
}

void StageTrace::command_writing() {
  if (open_ && records_.back().writing_ns == 0) records_.back().writing_ns = ns_of(Clock::now());
}

void StageTrace::command_written() {
  if (open_ && records_.back().command_ns == 0) records_.back().command_ns = ns_of(Clock::now());
}

void StageTrace::engine_done() {
  if (!open_) return;
  records_.back().engine_ns = ns_of(Clock::now());
  open_ = false;
}

void StageTrace::flushed() {
  if (unflushed_ == records_.size()) return;
  const std::int64_t now = ns_of(Clock::now());
  for (; unflushed_ < records_.size(); ++unflushed_) records_[unflushed_].flushed_ns = now;
}

void StageTrace::flushed_upto(std::size_t count, std::int64_t ns) {
  for (; unflushed_ < std::min(count, records_.size()); ++unflushed_) records_[unflushed_].flushed_ns = ns;
}

bool StageTrace::write(const std::string& path) const {
  std::ofstream out(path);
  out << "executor\tkind\tstamp_wall_ns\twoke_wall_ns\twoke_ns\twriting_ns\tcommand_ns\tengine_ns\tflushed_ns\n";
  for (const auto& r : records_)
    out << r.executor_id << '\t' << r.kind << '\t' << r.stamp_wall_ns << '\t' << r.woke_wall_ns << '\t' << r.woke_ns
        << '\t' << r.writing_ns << '\t' << r.command_ns << '\t' << r.engine_ns << '\t' << r.flushed_ns << '\n';
  out.flush();
  if (marks_.empty()) return static_cast<bool>(out);
  std::ofstream loop(path + ".loop");
  loop << "ns\twhat\tphase\n";
  std::vector<LoopMark> marks = marks_;
  std::stable_sort(marks.begin(), marks.end(), [](const LoopMark& a, const LoopMark& b) { return a.ns < b.ns; });
  for (const auto& m : marks) loop << m.ns << '\t' << m.what << '\t' << m.phase << '\n';
  loop.flush();
  return out && loop;
}

std::vector<LoopMark> StageTrace::read_marks(const std::string& path) {
  std::vector<LoopMark> out;
  std::ifstream in(path + ".loop");
  std::string line;
  if (!std::getline(in, line)) return out;  // the header
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    LoopMark m;
    std::string ns;
    if (std::getline(fields, ns, '\t') && std::getline(fields, m.what, '\t') && fields >> m.phase) {
      m.ns = std::stoll(ns);
      out.push_back(std::move(m));
    }
  }
  return out;
}

std::vector<StageRecord> StageTrace::read(const std::string& path) {
  std::vector<StageRecord> out;
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) return out;  // the header
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    StageRecord r;
    if (std::getline(fields, r.executor_id, '\t') && std::getline(fields, r.kind, '\t') &&
        fields >> r.stamp_wall_ns >> r.woke_wall_ns >> r.woke_ns >> r.writing_ns >> r.command_ns >> r.engine_ns >>
            r.flushed_ns)
      out.push_back(std::move(r));
  }
  return out;
}

}  // namespace rigger::task_controller
