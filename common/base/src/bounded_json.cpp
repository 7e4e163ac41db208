#include "rigger/base/bounded_json.hpp"

#include <fstream>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

namespace rigger {
namespace {

using Json = nlohmann::json;

void locate(std::string_view text, JsonParseError& error) {
  error.line = 1;
  error.column = 1;
  const std::size_t end = std::min(error.offset, text.size());
  for (std::size_t i = 0; i < end; ++i) {
    if (text[i] == '\n') {
      ++error.line;
      error.column = 1;
    } else {
      ++error.column;
    }
  }
}

// Offset of the first '[' or '{' (outside strings) that opens nesting level max_depth + 1.
// Only called after the SAX parser refused the depth, so the text up to there is valid JSON.
std::size_t find_depth_overflow(std::string_view text, std::size_t max_depth) {
  std::size_t depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) {
        return i;
      }
    } else if (c == ']' || c == '}') {
      if (depth > 0) {
        --depth;
      }
    }
  }
  return text.size();
}

// Builds the DOM like nlohmann's own SAX DOM parser, but refuses depth beyond the limit and
// duplicate keys as soon as they are seen, so nothing is allocated for a hostile tail.
class BoundedDomSax {
 public:
  using number_integer_t = Json::number_integer_t;
  using number_unsigned_t = Json::number_unsigned_t;
  using number_float_t = Json::number_float_t;
  using string_t = Json::string_t;
  using binary_t = Json::binary_t;

  explicit BoundedDomSax(std::size_t max_depth) : max_depth_(max_depth) {}

  bool null() { return value(nullptr); }
  bool boolean(bool v) { return value(v); }
  bool number_integer(number_integer_t v) { return value(v); }
  bool number_unsigned(number_unsigned_t v) { return value(v); }
  bool number_float(number_float_t v, const string_t& /*raw*/) { return value(v); }
  bool string(string_t& v) { return value(std::move(v)); }
  bool binary(binary_t& /*v*/) {
    fail(Failure::kSyntax, "binary values are not JSON");
    return false;
  }

  bool start_object(std::size_t /*elements*/) { return open(Json::value_t::object); }
  bool start_array(std::size_t /*elements*/) { return open(Json::value_t::array); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool key(string_t& k) {
    Json* top = stack_.back();
    if (top->contains(k)) {
      fail(Failure::kDuplicateKey, "duplicate key \"" + k + "\": every key may appear once in an object");
      failure_pointer_ = pointer() + "/" + escape_pointer_token(k);
      return false;
    }
    pending_key_ = std::move(k);
    return true;
  }

  bool parse_error(std::size_t position, const std::string& last_token, const Json::exception& ex) {
    std::string message = strip_prefix(ex.what());
    // `position` is just past the last byte read. An unexpected token is best shown where it
    // starts; a lexical error (bad byte, bad escape) where the bad byte is.
    const bool unexpected_token = message.find(" - unexpected ") != std::string::npos;
    if (unexpected_token && last_token.size() <= position) {
      failure_offset_ = position - last_token.size();
    } else {
      failure_offset_ = position > 0 ? position - 1 : 0;
    }
    fail(Failure::kSyntax, std::move(message));
    return false;
  }

  enum class Failure { kNone, kSyntax, kDepth, kDuplicateKey };

  Failure failure() const { return failure_; }
  const std::string& failure_message() const { return failure_message_; }
  const std::string& failure_pointer() const { return failure_pointer_; }
  std::size_t failure_offset() const { return failure_offset_; }
  Json take() { return std::move(root_); }

 private:
  static std::string strip_prefix(std::string what) {
    // "[json.exception.parse_error.101] parse error at line 1, column 3: …" → the part after ": ".
    const auto bracket = what.find("] ");
    if (bracket != std::string::npos && what.rfind("[json.exception", 0) == 0) {
      what.erase(0, bracket + 2);
    }
    const auto colon = what.find(": ");
    if (what.rfind("parse error", 0) == 0 && colon != std::string::npos) {
      what.erase(0, colon + 2);
    }
    return what;
  }

  void fail(Failure f, std::string message) {
    if (failure_ == Failure::kNone) {
      failure_ = f;
      failure_message_ = std::move(message);
    }
  }

  std::string pointer() const {
    std::string out;
    for (const auto& token : tokens_) {
      out += "/";
      out += escape_pointer_token(token);
    }
    return out;
  }

  template <typename V>
  Json* place(V&& v, std::string* token) {
    if (stack_.empty()) {
      root_ = Json(std::forward<V>(v));
      return &root_;
    }
    Json* top = stack_.back();
    if (top->is_array()) {
      auto& array = top->get_ref<Json::array_t&>();
      if (token != nullptr) {
        *token = std::to_string(array.size());
      }
      array.emplace_back(std::forward<V>(v));
      return &array.back();
    }
    if (token != nullptr) {
      *token = pending_key_;
    }
    Json& slot = (*top)[pending_key_];
    slot = Json(std::forward<V>(v));
    return &slot;
  }

  template <typename V>
  bool value(V&& v) {
    place(std::forward<V>(v), nullptr);
    return true;
  }

  bool open(Json::value_t type) {
    if (stack_.size() + 1 > max_depth_) {
      fail(Failure::kDepth, "nesting deeper than " + std::to_string(max_depth_) +
                                " levels: expected at most " + std::to_string(max_depth_) +
                                " nested arrays/objects");
      failure_pointer_ = pointer();
      return false;
    }
    std::string token;
    Json* slot = place(type, stack_.empty() ? nullptr : &token);
    if (!stack_.empty()) {
      tokens_.push_back(std::move(token));
    }
    stack_.push_back(slot);
    return true;
  }

  bool close() {
    // Every open container but the top-level one has a token, so closing one drops one.
    stack_.pop_back();
    if (!tokens_.empty()) {
      tokens_.pop_back();
    }
    return true;
  }

  std::size_t max_depth_;
  Json root_;
  std::vector<Json*> stack_;
  std::vector<std::string> tokens_;
  std::string pending_key_;
  Failure failure_ = Failure::kNone;
  std::string failure_message_;
  std::string failure_pointer_;
  std::size_t failure_offset_ = 0;
};

}  // namespace

std::string JsonParseError::to_string() const {
  std::ostringstream out;
  if (!source.empty()) {
    out << source << ":";
  }
  out << line << ":" << column << ": ";
  if (!pointer.empty()) {
    out << "at " << pointer << ": ";
  }
  out << message;
  return out.str();
}

std::string escape_pointer_token(std::string_view token) {
  std::string out;
  out.reserve(token.size());
  for (const char c : token) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

JsonParseResult parse_json_bounded(std::string_view text, const JsonLimits& limits) {
  JsonParseResult result;
  if (text.size() > limits.max_bytes) {
    JsonParseError error;
    error.offset = limits.max_bytes;
    error.message = "input is " + std::to_string(text.size()) + " bytes: expected at most " +
                    std::to_string(limits.max_bytes) + " bytes";
    locate(text.substr(0, std::min<std::size_t>(text.size(), limits.max_bytes)), error);
    result.error = std::move(error);
    return result;
  }
  BoundedDomSax sax(limits.max_depth);
  const bool ok = Json::sax_parse(text.begin(), text.end(), &sax, Json::input_format_t::json,
                                  /*strict=*/true, /*ignore_comments=*/false);
  if (ok && sax.failure() == BoundedDomSax::Failure::kNone) {
    result.value = sax.take();
    return result;
  }
  JsonParseError error;
  error.message = sax.failure_message();
  error.pointer = sax.failure_pointer();
  switch (sax.failure()) {
    case BoundedDomSax::Failure::kDepth:
      error.offset = find_depth_overflow(text, limits.max_depth);
      break;
    case BoundedDomSax::Failure::kSyntax:
      error.offset = sax.failure_offset();
      break;
    case BoundedDomSax::Failure::kDuplicateKey:
    case BoundedDomSax::Failure::kNone:
      // The SAX interface does not expose positions; the pointer names the place instead.
      error.offset = 0;
      break;
  }
  if (error.message.empty()) {
    error.message = "not valid JSON";
  }
  locate(text, error);
  result.error = std::move(error);
  return result;
}

JsonParseResult parse_json_file_bounded(const std::filesystem::path& path, const JsonLimits& limits) {
  JsonParseResult result;
  auto fail = [&](std::string message) {
    JsonParseError error;
    error.source = path.string();
    error.message = std::move(message);
    result.error = std::move(error);
    return result;
  };
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) {
    return fail("cannot read file: " + ec.message());
  }
  if (size > limits.max_bytes) {
    return fail("file is " + std::to_string(size) + " bytes: expected at most " +
                std::to_string(limits.max_bytes) + " bytes");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return fail("cannot open file for reading");
  }
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) {
    return fail("file changed size while being read");
  }
  result = parse_json_bounded(text, limits);
  if (result.error) {
    result.error->source = path.string();
  }
  return result;
}

}  // namespace rigger
