#include "rigger/skill/predicate.hpp"

namespace rigger::skill {
namespace {

bool is_name_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool is_name_char(char c) { return is_name_start(c) || (c >= '0' && c <= '9'); }
bool is_atom_char(char c) {
  return is_name_char(c) || c == '.' || c == '/' || c == ':' || c == '-';
}

class Scanner {
 public:
  explicit Scanner(std::string_view text) : text_(text) {}

  void skip_space() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t')) {
      ++pos_;
    }
  }
  bool at_end() const { return pos_ >= text_.size(); }
  char peek() const { return at_end() ? '\0' : text_[pos_]; }
  bool accept(char c) {
    if (peek() == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  std::string take_while(bool (*predicate)(char)) {
    const std::size_t begin = pos_;
    while (!at_end() && predicate(text_[pos_])) {
      ++pos_;
    }
    return std::string(text_.substr(begin, pos_ - begin));
  }
  std::size_t position() const { return pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

}  // namespace

std::string Predicate::to_string() const {
  std::string out = negated ? "!" : "";
  out += name;
  out += "(";
  for (std::size_t i = 0; i < args.size(); ++i) {
    out += (i == 0 ? "" : ",");
    out += args[i];
  }
  out += ")";
  return out;
}

std::vector<std::string> Predicate::referenced_params() const {
  std::vector<std::string> out;
  for (const auto& arg : args) {
    if (!arg.empty() && arg.front() == '$') {
      out.push_back(arg.substr(1));
    }
  }
  return out;
}

std::optional<Fact> Predicate::ground(const nlohmann::json& params) const {
  std::string out = name + "(";
  for (std::size_t i = 0; i < args.size(); ++i) {
    out += (i == 0 ? "" : ",");
    const std::string& arg = args[i];
    if (arg.empty() || arg.front() != '$') {
      out += arg;
      continue;
    }
    const std::string param = arg.substr(1);
    if (!params.is_object() || !params.contains(param)) {
      return std::nullopt;
    }
    const auto& value = params[param];
    if (value.is_string()) {
      out += value.get<std::string>();
    } else if (value.is_number() || value.is_boolean()) {
      out += value.dump();
    } else {
      return std::nullopt;
    }
  }
  out += ")";
  return out;
}

std::optional<Predicate> parse_predicate(std::string_view text, std::string* error) {
  Scanner s(text);
  auto fail = [&](const std::string& what) -> std::optional<Predicate> {
    if (error != nullptr) {
      *error = "at character " + std::to_string(s.position() + 1) + " of \"" + std::string(text) + "\": expected " +
               what + " (grammar: [!]name(arg, …) where arg is $param or an atom)";
    }
    return std::nullopt;
  };
  Predicate p;
  s.skip_space();
  p.negated = s.accept('!');
  s.skip_space();
  if (!is_name_start(s.peek())) {
    return fail("a predicate name");
  }
  p.name = s.take_while(is_name_char);
  s.skip_space();
  if (s.accept('(')) {
    s.skip_space();
    if (!s.accept(')')) {
      while (true) {
        s.skip_space();
        std::string arg;
        if (s.accept('$')) {
          if (!is_name_start(s.peek())) {
            return fail("a parameter name after '$'");
          }
          arg = "$" + s.take_while(is_name_char);
        } else {
          arg = s.take_while(is_atom_char);
          if (arg.empty()) {
            return fail("an argument");
          }
        }
        p.args.push_back(std::move(arg));
        s.skip_space();
        if (s.accept(')')) {
          break;
        }
        if (!s.accept(',')) {
          return fail("',' or ')'");
        }
      }
    }
  }
  s.skip_space();
  if (!s.at_end()) {
    return fail("the end of the predicate");
  }
  return p;
}

}  // namespace rigger::skill
