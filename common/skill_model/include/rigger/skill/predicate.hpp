#pragma once
/// Pre- and postconditions: predicates over world facts, e.g. "attached(robot,$object)".
///
/// Grammar (whitespace allowed between tokens):
///   predicate := ["!"] name ["(" [arg ("," arg)*] ")"]
///   name      := [A-Za-z_][A-Za-z0-9_]*
///   arg       := "$" name            (the value of that parameter, substituted when grounded)
///              | [A-Za-z0-9_./:-]+   (a literal atom: "robot", "load/grasp_side")
/// "!" marks a deleted fact and is allowed in postconditions only. A ground predicate (a *fact*)
/// has its canonical text form "name(arg1,arg2)" with no spaces; "ready" and "ready()" are equal.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace rigger::skill {

/// A ground predicate in canonical text form, e.g. "attached(robot,load)".
using Fact = std::string;

struct Predicate {
  std::string name;
  std::vector<std::string> args;  ///< literal atoms or "$param" references
  bool negated = false;           ///< "!p(...)": the fact no longer holds afterwards

  /// Canonical text: ["!"]name(arg,arg).
  std::string to_string() const;
  /// Names of the parameters referenced by "$name" arguments, in order.
  std::vector<std::string> referenced_params() const;
  /// The fact this predicate denotes with its "$param" arguments replaced by the parameter
  /// values in `params` (strings as-is, numbers and booleans in JSON form). The negation mark
  /// is not part of the fact. std::nullopt when a referenced parameter is missing or is not a
  /// scalar (object, array, null).
  std::optional<Fact> ground(const nlohmann::json& params) const;

  friend bool operator==(const Predicate& a, const Predicate& b) {
    return a.name == b.name && a.args == b.args && a.negated == b.negated;
  }
};

/// Parses a predicate. On failure returns std::nullopt and, when `error` is not null, what was
/// expected and at which character.
std::optional<Predicate> parse_predicate(std::string_view text, std::string* error = nullptr);

}  // namespace rigger::skill
