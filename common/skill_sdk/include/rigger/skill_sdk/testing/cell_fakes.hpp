#pragma once
// Fakes of the cell devices (cell_devices.hpp) for unit tests of skill FSMs: every operation is
// recorded and completed by the test; nothing happens on its own.

#include <algorithm>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/skill_sdk/testing/fakes.hpp"

namespace rigger::skill_sdk::testing {

class FakeCrane final : public CraneMonitor {
 public:
  OpId check_health(std::chrono::nanoseconds, std::chrono::nanoseconds, OpCallback done) override {
    checks_[++next_] = std::move(done);
    return next_;
  }
  OpId watch_health(std::chrono::nanoseconds, OpCallback on_problem) override {
    watches_[++next_] = std::move(on_problem);
    return next_;
  }
  OpId request_external(std::chrono::nanoseconds, OpCallback done) override {
    ++external_requests;
    externals_[++next_] = std::move(done);
    return next_;
  }
  void cancel(OpId id) override { checks_.erase(id) || watches_.erase(id) || externals_.erase(id); }

  /// Completes the oldest pending health check; false when none is pending.
  bool complete_check(const OpResult& r) { return complete(checks_, r); }
  bool complete_external(const OpResult& r) { return complete(externals_, r); }
  /// Reports a problem to every watch (each fires once); returns how many there were.
  std::size_t problem(const std::string& message) {
    auto watches = std::move(watches_);
    watches_.clear();
    for (auto& [id, cb] : watches) cb(OpResult::failure(kCraneFault, message));
    return watches.size();
  }
  std::size_t pending_checks() const { return checks_.size(); }
  std::size_t watches() const { return watches_.size(); }
  std::size_t pending_externals() const { return externals_.size(); }
  int external_requests = 0;

 private:
  static bool complete(std::map<OpId, OpCallback>& ops, const OpResult& r) {
    if (ops.empty()) return false;
    auto cb = std::move(ops.begin()->second);
    ops.erase(ops.begin());
    cb(r);
    return true;
  }
  std::map<OpId, OpCallback> checks_, watches_, externals_;
  OpId next_ = 0;
};

class FakeTracker final : public VisionTracker {
 public:
  WallTime command(TrackerRequest request, const std::string& object_id) override {
    now += std::chrono::milliseconds(1);
    commands.emplace_back(request, object_id);
    return now;
  }
  OpId watch(const std::string& object_id, std::function<void(const TrackedObjectSample&)> on_sample) override {
    watches_[++next_] = {object_id, std::move(on_sample)};
    return next_;
  }
  void cancel(OpId id) override { watches_.erase(id); }

  /// Offers `s` to every watch of its object.
  void publish(const TrackedObjectSample& s) {
    std::vector<OpId> ids;
    for (const auto& [id, w] : watches_) ids.push_back(id);
    for (OpId id : ids) {
      auto it = watches_.find(id);
      if (it == watches_.end() || it->second.first != s.object_id) continue;
      auto cb = it->second.second;
      cb(s);
    }
  }
  /// A sample of `object` taken `after` past the newest command.
  TrackedObjectSample sample(const std::string& object, bool tracked, double quality,
                             std::chrono::milliseconds after = std::chrono::milliseconds(5)) const {
    TrackedObjectSample s;
    s.object_id = object;
    s.frame = "world";
    s.stamp = now + after;
    s.tracked = tracked;
    s.quality = tracked ? quality : 0.0;
    if (tracked) s.pose.translation() = Eigen::Vector3d(1.0, 2.0, 0.5);
    return s;
  }
  int count(TrackerRequest request) const {
    return static_cast<int>(
        std::count_if(commands.begin(), commands.end(), [request](const auto& c) { return c.first == request; }));
  }
  /// Commands `request` for `object` only.
  int count(TrackerRequest request, const std::string& object) const {
    return static_cast<int>(std::count_if(commands.begin(), commands.end(), [&](const auto& c) {
      return c.first == request && c.second == object;
    }));
  }
  std::size_t watches() const { return watches_.size(); }

  WallTime now = WallTime(std::chrono::seconds(1'700'000'000));
  std::vector<std::pair<TrackerRequest, std::string>> commands;

 private:
  std::map<OpId, std::pair<std::string, std::function<void(const TrackedObjectSample&)>>> watches_;
  OpId next_ = 0;
};

class FakeAdmittance final : public AdmittanceController {
 public:
  OpId command(const AdmittanceRequest& request, std::chrono::nanoseconds, OpCallback done) override {
    requests.push_back(request);
    pending_[++next_] = {request, std::move(done)};
    return next_;
  }
  OpId watch(std::function<void(const AdmittanceSnapshot&)> on_state) override {
    watches_[++next_] = std::move(on_state);
    return next_;
  }
  void cancel(OpId id) override { pending_.erase(id) || watches_.erase(id); }

  /// Completes the newest pending command; false when none is pending.
  bool complete(const OpResult& r) {
    if (pending_.empty()) return false;
    auto it = std::prev(pending_.end());
    auto cb = std::move(it->second.second);
    pending_.erase(it);
    cb(r);
    return true;
  }
  /// The newest pending command's request, or nullptr.
  const AdmittanceRequest* pending() const { return pending_.empty() ? nullptr : &pending_.rbegin()->second.first; }
  void publish(const AdmittanceSnapshot& s) {
    std::vector<OpId> ids;
    for (const auto& [id, w] : watches_) ids.push_back(id);
    for (OpId id : ids) {
      auto it = watches_.find(id);
      if (it == watches_.end()) continue;
      auto cb = it->second;
      cb(s);
    }
  }
  int offs() const {
    return static_cast<int>(std::count_if(requests.begin(), requests.end(),
                                          [](const auto& r) { return r.mode == AdmittanceModeRequest::kOff; }));
  }
  std::size_t watches() const { return watches_.size(); }
  std::vector<AdmittanceRequest> requests;

 private:
  std::map<OpId, std::pair<AdmittanceRequest, OpCallback>> pending_;
  std::map<OpId, std::function<void(const AdmittanceSnapshot&)>> watches_;
  OpId next_ = 0;
};

class FakeOperator final : public OperatorPanel {
 public:
  struct Prompt {
    OperatorPromptSpec spec;
    std::function<void(std::optional<std::string>)> done;
    bool withdrawn = false;
  };
  OpId ask(const OperatorPromptSpec& spec, std::chrono::nanoseconds,
           std::function<void(std::optional<std::string>)> done) override {
    prompts[++next_] = {spec, std::move(done), false};
    return next_;
  }
  void withdraw(OpId id) override {
    auto it = prompts.find(id);
    if (it == prompts.end() || it->second.withdrawn) return;
    it->second.withdrawn = true;
    it->second.done = nullptr;
  }
  /// Answers the newest active prompt still waiting (std::nullopt: its timeout); false when none.
  bool answer(std::optional<std::string> a) {
    for (auto it = prompts.rbegin(); it != prompts.rend(); ++it) {
      if (it->second.withdrawn || !it->second.done) continue;
      auto cb = std::move(it->second.done);
      it->second.done = nullptr;
      cb(std::move(a));
      return true;
    }
    return false;
  }
  std::size_t active() const {
    return static_cast<std::size_t>(
        std::count_if(prompts.begin(), prompts.end(), [](const auto& p) { return !p.second.withdrawn; }));
  }
  const Prompt* newest() const { return prompts.empty() ? nullptr : &prompts.rbegin()->second; }
  std::map<OpId, Prompt> prompts;

 private:
  OpId next_ = 0;
};

class FakeWorldAccess final : public WorldAccess {
 public:
  struct Update {
    std::string entity, parent;
    Eigen::Isometry3d pose;
    WallTime stamp;
    double quality;
    OpCallback done;
    bool localized = true;  ///< false: a mark_unlocalized (no pose)
  };
  OpId features(const std::string& entity, std::chrono::nanoseconds,
                std::function<void(const OpResult&, const nlohmann::json&)> done) override {
    feature_requests_[++next_] = {entity, std::move(done)};
    return next_;
  }
  OpId update_pose(const std::string& entity, const std::string& parent_frame, const Eigen::Isometry3d& pose,
                   WallTime stamp, double quality, std::chrono::nanoseconds, OpCallback done) override {
    updates_[++next_] = {entity, parent_frame, pose, stamp, quality, std::move(done)};
    return next_;
  }
  OpId mark_unlocalized(const std::string& entity, WallTime stamp, std::chrono::nanoseconds,
                        OpCallback done) override {
    updates_[++next_] = {entity, "", Eigen::Isometry3d::Identity(), stamp, -1.0, std::move(done), false};
    return next_;
  }
  OpId running_cell(std::chrono::nanoseconds,
                    std::function<void(const OpResult&, const CellDocument&)> done) override {
    cell_reads_[++next_] = std::move(done);
    return next_;
  }
  OpId propose_cell(const CellProposal& proposal, std::chrono::nanoseconds,
                    std::function<void(const OpResult&, const CellProposalAnswer&)> done) override {
    proposals.push_back(proposal);
    cell_proposals_[++next_] = std::move(done);
    return next_;
  }
  void cancel(OpId id) override {
    feature_requests_.erase(id) || updates_.erase(id) || cell_reads_.erase(id) || cell_proposals_.erase(id);
  }

  /// Answers the oldest pending running_cell(); false when none is pending.
  bool answer_running_cell(const OpResult& r, const CellDocument& document) {
    if (cell_reads_.empty()) return false;
    auto cb = std::move(cell_reads_.begin()->second);
    cell_reads_.erase(cell_reads_.begin());
    cb(r, document);
    return true;
  }
  /// Answers the oldest pending propose_cell(); false when none is pending.
  bool answer_proposal(const OpResult& r, const CellProposalAnswer& answer = {}) {
    if (cell_proposals_.empty()) return false;
    auto cb = std::move(cell_proposals_.begin()->second);
    cell_proposals_.erase(cell_proposals_.begin());
    cb(r, answer);
    return true;
  }
  /// Every proposal made, in order (answered or not).
  std::vector<CellProposal> proposals;

  /// The entity of the oldest pending features request ("" when none).
  std::string features_entity() const {
    return feature_requests_.empty() ? "" : feature_requests_.begin()->second.first;
  }
  bool answer_features(const OpResult& r, const nlohmann::json& f) {
    if (feature_requests_.empty()) return false;
    auto cb = std::move(feature_requests_.begin()->second.second);
    feature_requests_.erase(feature_requests_.begin());
    cb(r, f);
    return true;
  }
  const Update* pending_update() const { return updates_.empty() ? nullptr : &updates_.begin()->second; }
  bool answer_update(const OpResult& r) {
    if (updates_.empty()) return false;
    auto cb = std::move(updates_.begin()->second.done);
    updates_.erase(updates_.begin());
    cb(r);
    return true;
  }

 private:
  std::map<OpId, std::pair<std::string, std::function<void(const OpResult&, const nlohmann::json&)>>> feature_requests_;
  std::map<OpId, Update> updates_;
  std::map<OpId, std::function<void(const OpResult&, const CellDocument&)>> cell_reads_;
  std::map<OpId, std::function<void(const OpResult&, const CellProposalAnswer&)>> cell_proposals_;
  OpId next_ = 0;
};

}  // namespace rigger::skill_sdk::testing
