#include "rigger/dds/sample_json.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

#include "sample_type.hpp"

namespace rigger::dds {
namespace {

// ---------------------------------------------------------------------------------------------------
// The walk over a sample: a bounded tree of values, printed as JSON or text.

struct Value {
  enum class Type { kNull, kBool, kNumber, kString, kObject, kArray } type = Type::kNull;
  std::string text;                                    // number text, string content, "true"/"false"
  std::vector<std::pair<std::string, Value>> members;  // object
  std::vector<Value> items;                            // array
};

template <typename T>
T load(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

template <typename T>
std::string number(T v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

class Walker {
 public:
  explicit Walker(const FormatLimits& limits) : limits_(limits) {}
  bool truncated() const { return used_ >= limits_.max_output; }

  Value value(const TypeNode& t, const char* p) {
    Value v;
    switch (t.kind) {
      case Kind::kBool:
        v.type = Value::Type::kBool;
        v.text = *p ? "true" : "false";
        break;
      case Kind::kSigned:
        v.type = Value::Type::kNumber;
        v.text = t.size == 1   ? number(load<std::int8_t>(p))
                 : t.size == 2 ? number(load<std::int16_t>(p))
                 : t.size == 4 ? number(load<std::int32_t>(p))
                               : number(load<std::int64_t>(p));
        break;
      case Kind::kUnsigned:
      case Kind::kBitmask:
        v.type = Value::Type::kNumber;
        v.text = number(unsigned_at(p, t.size));
        break;
      case Kind::kFloat: {
        const double d = t.size == 4 ? static_cast<double>(load<float>(p)) : load<double>(p);
        if (std::isfinite(d)) {
          v.type = Value::Type::kNumber;
          v.text = t.size == 4 ? number(load<float>(p)) : number(d);
        } else {
          v.type = Value::Type::kNull;  // JSON has no NaN; the text form says which
          v.text = std::isnan(d) ? "nan" : d > 0 ? "inf" : "-inf";
        }
        break;
      }
      case Kind::kEnum: {
        const auto raw = static_cast<std::int64_t>(t.size == 1   ? load<std::uint8_t>(p)
                                                   : t.size == 2 ? load<std::uint16_t>(p)
                                                                 : load<std::uint32_t>(p));
        const auto it = t.names.find(raw);
        if (it != t.names.end()) {
          v.type = Value::Type::kString;
          v.text = it->second;
        } else {  // a value outside the enum: show the number rather than a wrong name
          v.type = Value::Type::kNumber;
          v.text = number(raw);
        }
        break;
      }
      case Kind::kString: {
        const char* s = load<const char*>(p);
        if (s == nullptr && t.optional_string) return v;
        string_value(v, s == nullptr ? "" : s, s == nullptr ? 0 : std::strlen(s));
        break;
      }
      case Kind::kBoundedString:
        string_value(v, p, strnlen(p, t.size));
        break;
      case Kind::kStruct:
        v.type = Value::Type::kObject;
        for (const auto& m : t.members) v.members.emplace_back(m.name, member(m, p));
        break;
      case Kind::kUnion: {
        v.type = Value::Type::kObject;
        v.members.emplace_back("discriminator", value(*t.discriminator, p + t.discriminator_offset));
        const std::int64_t d = discriminator(*t.discriminator, p + t.discriminator_offset);
        const UnionCase* chosen = nullptr;
        for (const auto& c : t.cases)
          if (!c.is_default && c.label == d) chosen = &c;
        if (chosen == nullptr)
          for (const auto& c : t.cases)
            if (c.is_default) chosen = &c;
        if (chosen != nullptr) v.members.emplace_back(chosen->member.name, member(chosen->member, p));
        break;
      }
      case Kind::kSequence: {
        const auto& seq = *reinterpret_cast<const dds_sequence_t*>(p);
        // A null buffer with a length is a malformed sample, not something to dereference.
        elements(v, *t.element, reinterpret_cast<const char*>(seq._buffer), seq._buffer ? seq._length : 0);
        break;
      }
      case Kind::kArray:
        elements(v, *t.element, p, t.count);
        break;
    }
    used_ += v.text.size() + 2;
    return v;
  }

 private:
  static std::uint64_t unsigned_at(const char* p, std::uint32_t size) {
    return size == 1   ? load<std::uint8_t>(p)
           : size == 2 ? load<std::uint16_t>(p)
           : size == 4 ? load<std::uint32_t>(p)
                       : load<std::uint64_t>(p);
  }
  static std::int64_t discriminator(const TypeNode& t, const char* p) {
    if (t.kind == Kind::kSigned)
      return t.size == 1   ? load<std::int8_t>(p)
             : t.size == 2 ? load<std::int16_t>(p)
             : t.size == 4 ? load<std::int32_t>(p)
                           : load<std::int64_t>(p);
    return static_cast<std::int64_t>(unsigned_at(p, t.size));
  }

  Value member(const Member& m, const char* base) {
    const char* p = base + m.offset;
    if (m.external) {
      p = load<const char*>(p);
      if (p == nullptr) return Value{};  // unset @optional
    }
    return value(*m.type, p);
  }

  void string_value(Value& v, const char* s, std::size_t n) {
    v.type = Value::Type::kString;
    const std::size_t room = truncated() ? 0 : limits_.max_string;
    if (n <= room) {
      v.text.assign(s, n);
    } else {
      // Cut on a UTF-8 character boundary.
      std::size_t cut = room;
      while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xc0) == 0x80) --cut;
      v.text.assign(s, cut);
      v.text += "\xe2\x80\xa6";  // …
    }
  }

  void elements(Value& v, const TypeNode& elem, const char* p, std::uint32_t n) {
    const std::size_t shown = truncated() ? 0 : std::min<std::size_t>(n, limits_.max_elements);
    Value items;
    items.type = Value::Type::kArray;
    for (std::size_t i = 0; i < shown && !truncated(); ++i) items.items.push_back(value(elem, p + i * elem.stride));
    if (items.items.size() == n) {
      v = std::move(items);
      return;
    }
    v.type = Value::Type::kObject;
    Value length;
    length.type = Value::Type::kNumber;
    length.text = number(n);
    v.members.emplace_back("length", std::move(length));
    v.members.emplace_back("first", std::move(items));
  }

  const FormatLimits& limits_;
  std::size_t used_ = 0;
};

void json_string(std::string& out, const std::string& s) {
  out += '"';
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

void json(std::string& out, const Value& v) {
  switch (v.type) {
    case Value::Type::kNull:
      out += "null";
      break;
    case Value::Type::kBool:
    case Value::Type::kNumber:
      out += v.text;
      break;
    case Value::Type::kString:
      json_string(out, v.text);
      break;
    case Value::Type::kObject: {
      out += '{';
      bool first = true;
      for (const auto& [k, m] : v.members) {
        if (!first) out += ',';
        first = false;
        json_string(out, k);
        out += ':';
        json(out, m);
      }
      out += '}';
      break;
    }
    case Value::Type::kArray: {
      out += '[';
      for (std::size_t i = 0; i < v.items.size(); ++i) {
        if (i) out += ',';
        json(out, v.items[i]);
      }
      out += ']';
      break;
    }
  }
}

bool is_scalar(const Value& v) {
  return v.type != Value::Type::kObject && v.type != Value::Type::kArray;
}

// Text: a scalar as it reads ("nan" for a non-finite float, strings quoted only when empty).
std::string scalar_text(const Value& v) {
  if (v.type == Value::Type::kNull) return v.text.empty() ? "null" : v.text;
  if (v.type == Value::Type::kString) {
    std::string out;
    if (v.text.empty() || v.text.find_first_of("\n\r\t\"") != std::string::npos) {
      json_string(out, v.text);
      return out;
    }
    return v.text;
  }
  return v.text;
}

void text(std::string& out, const Value& v, int indent) {
  const std::string pad(static_cast<std::size_t>(indent) * 2, ' ');
  if (v.type == Value::Type::kObject) {
    for (const auto& [k, m] : v.members) {
      out += pad + k + ":";
      if (is_scalar(m)) {
        out += " " + scalar_text(m) + "\n";
      } else if (m.type == Value::Type::kArray &&
                 (m.items.empty() || std::all_of(m.items.begin(), m.items.end(), is_scalar))) {
        out += " [";
        for (std::size_t i = 0; i < m.items.size(); ++i) out += (i ? ", " : "") + scalar_text(m.items[i]);
        out += "]\n";
      } else {
        out += "\n";
        text(out, m, indent + 1);
      }
    }
    return;
  }
  if (v.type == Value::Type::kArray) {
    for (const auto& item : v.items) {
      if (is_scalar(item)) {
        out += pad + "- " + scalar_text(item) + "\n";
      } else {
        out += pad + "-\n";
        text(out, item, indent + 1);
      }
    }
    return;
  }
  out += pad + scalar_text(v) + "\n";
}

}  // namespace

SampleFormat::SampleFormat(const dds_topic_descriptor_t& descriptor) : type_name_(descriptor.m_typename) {
  root_ = compile_sample_type(descriptor, type_name_);
}

SampleFormat::~SampleFormat() = default;
SampleFormat::SampleFormat(SampleFormat&&) noexcept = default;
SampleFormat& SampleFormat::operator=(SampleFormat&&) noexcept = default;

std::string SampleFormat::to_json(const void* sample, const FormatLimits& limits) const {
  Walker walker(limits);
  Value v = walker.value(*root_, static_cast<const char*>(sample));
  if (walker.truncated() && v.type == Value::Type::kObject) {
    Value flag;
    flag.type = Value::Type::kBool;
    flag.text = "true";
    v.members.emplace_back("truncated", std::move(flag));
  }
  std::string out;
  json(out, v);
  return out;
}

std::string SampleFormat::to_text(const void* sample, const FormatLimits& limits) const {
  Walker walker(limits);
  const Value v = walker.value(*root_, static_cast<const char*>(sample));
  std::string out;
  text(out, v, 0);
  if (walker.truncated()) out += "\xe2\x80\xa6 (cut at " + std::to_string(limits.max_output) + " bytes)\n";
  return out;
}

}  // namespace rigger::dds
