#pragma once
/// @file
/// Operator decisions (OperatorDecision nodes): the controller asks on rigger/operator/prompt and takes
/// answers from rigger/operator/response. A prompt id names the task, the node and the node's
/// activation ("<task>#<node>#<activation>"), so an answer to an earlier activation of a node (before a
/// Retry) is told from one to the current. PromptId and option_index are pure logic; PromptWriter
/// writes the prompts.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rigger/bt/port.hpp"
#include "rigger/bt/tree_spec.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/operator.hpp"

namespace rigger::task_controller {

struct PromptId {
  /// Longer texts are not ours (task ids are at most 128 characters, node ids are paths of indices).
  static constexpr std::size_t kMaxLength = 4096;

  std::string task_id;
  std::string node_id;
  bt::Activation activation = 0;

  /// "<task>#<node>#<activation>".
  std::string str() const;
  /// The id of `text` when it is one of the controller's: three non-empty parts, the last a decimal
  /// activation; nullopt for anything else (another service's prompt, garbage, too long).
  static std::optional<PromptId> parse(std::string_view text);

  friend bool operator==(const PromptId& a, const PromptId& b) {
    return a.task_id == b.task_id && a.node_id == b.node_id && a.activation == b.activation;
  }
};

/// The index of `answer` among `options` (exact match), or nullopt.
std::optional<std::size_t> option_index(const std::vector<std::string>& options, const std::string& answer);
/// `"a", "b", "c"`: the options as an operator would type them, for error messages.
std::string quoted_options(const std::vector<std::string>& options);

/// Writes the controller's prompts (state QoS: a late-joining operator UI sees the open ones).
class PromptWriter {
 public:
  /// @throws DdsError.
  explicit PromptWriter(const dds::Participant& participant);
  /// Publishes the prompt of `spec` (active) or its withdrawal (inactive): title `spec.name`, text
  /// `spec.prompt`, options `spec.options`; `kind` "decision" (an OperatorDecision node) or "resume" (a
  /// task resumed after a crash, whose `details_json` lists what was done and what will run). Returns
  /// false when the write failed.
  bool write(const PromptId& id, const bt::NodeSpec& spec, bool active, const std::string& kind = "decision",
             const std::string& details_json = "");

 private:
  dds::Writer<rigger_operator_ui_OperatorPrompt> prompts_;
};

}  // namespace rigger::task_controller
