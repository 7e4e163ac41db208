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

#include <dds/ddsi/ddsi_sertype.h>
#include <dds/ddsi/ddsi_typelib.h>
#include <dds/ddsi/ddsi_xt_typeinfo.h>
#include <dds/ddsi/ddsi_xt_typemap.h>

namespace rigger::dds {

// ---------------------------------------------------------------------------------------------------
// The compiled type: what the walk over a sample needs, built once from the ops and the type objects.

enum class Kind {
  kBool,
  kSigned,
  kUnsigned,
  kFloat,
  kEnum,
  kBitmask,
  kString,
  kBoundedString,
  kStruct,
  kUnion,
  kSequence,
  kArray
};

using NodePtr = std::shared_ptr<const TypeNode>;

struct Member {
  std::string name;
  std::uint32_t offset = 0;
  bool external = false;  // stored behind a pointer (@optional, @external): null means unset
  NodePtr type;
};

struct UnionCase {
  std::int64_t label = 0;
  bool is_default = false;
  Member member;
};

struct TypeNode {
  Kind kind = Kind::kBool;
  std::uint32_t size = 0;    // scalar/enum/bitmask storage bytes; bounded string capacity (with the NUL)
  std::uint32_t count = 0;   // array length
  std::uint32_t stride = 0;  // sequence/array element size in memory
  bool optional_string = false;
  std::vector<Member> members;                // struct
  std::map<std::int64_t, std::string> names;  // enum
  NodePtr element;                            // sequence/array
  NodePtr discriminator;                      // union
  std::uint32_t discriminator_offset = 0;
  std::vector<UnionCase> cases;
};

namespace {

constexpr int kMaxDepth = 32;

[[noreturn]] void fail(const std::string& type, const std::string& what) {
  throw std::invalid_argument("cannot format samples of " + type + ": " + what);
}

std::uint32_t scalar_size(std::uint32_t code) {
  switch (code) {
    case DDS_OP_VAL_1BY:
    case DDS_OP_VAL_BLN:
      return 1;
    case DDS_OP_VAL_2BY:
      return 2;
    case DDS_OP_VAL_4BY:
      return 4;
    case DDS_OP_VAL_8BY:
      return 8;
    default:
      return 0;
  }
}

class Compiler {
 public:
  Compiler(const DDS_XTypes_TypeMapping& map, std::string type) : map_(map), type_(std::move(type)) {}

  const DDS_XTypes_CompleteTypeObject* by_name(const std::string& name) const {
    const auto& pairs = map_.identifier_object_pair_complete;
    for (std::uint32_t i = 0; i < pairs._length; ++i) {
      const auto& to = pairs._buffer[i].type_object;
      if (to._d != DDS_XTypes_EK_COMPLETE) continue;
      const auto& c = to._u.complete;
      const char* n = c._d == DDS_XTypes_TK_STRUCTURE ? c._u.struct_type.header.detail.type_name
                      : c._d == DDS_XTypes_TK_UNION   ? c._u.union_type.header.detail.type_name
                                                      : nullptr;
      if (n != nullptr && name == n) return &c;
    }
    return nullptr;
  }

  /// The struct or union whose ops start at `ops`.
  NodePtr aggregate(const std::uint32_t* ops, const DDS_XTypes_CompleteTypeObject* to, int depth) {
    if (depth > kMaxDepth) fail(type_, "nesting deeper than " + std::to_string(kMaxDepth));
    if (to == nullptr) fail(type_, "a nested type has no type object");
    if (to->_d == DDS_XTypes_TK_STRUCTURE) return structure(ops, to->_u.struct_type, depth);
    if (to->_d == DDS_XTypes_TK_UNION) return union_type(ops, to->_u.union_type, depth);
    fail(type_, "unexpected aggregate kind " + std::to_string(to->_d));
  }

 private:
  /// The complete type object an identifier names (aliases followed), or nullptr for a plain one.
  const DDS_XTypes_CompleteTypeObject* resolve(const DDS_XTypes_TypeIdentifier& id, int hops = 0) const {
    if (id._d != DDS_XTypes_EK_COMPLETE) return nullptr;
    const auto& pairs = map_.identifier_object_pair_complete;
    for (std::uint32_t i = 0; i < pairs._length; ++i) {
      const auto& ti = pairs._buffer[i].type_identifier;
      if (ti._d != DDS_XTypes_EK_COMPLETE ||
          std::memcmp(ti._u.equivalence_hash, id._u.equivalence_hash, sizeof(DDS_XTypes_EquivalenceHash)) != 0)
        continue;
      const auto& to = pairs._buffer[i].type_object;
      if (to._d != DDS_XTypes_EK_COMPLETE) return nullptr;
      if (to._u.complete._d == DDS_XTypes_TK_ALIAS && hops < kMaxDepth)
        return resolve_alias(to._u.complete._u.alias_type.body.common.related_type, hops + 1);
      return &to._u.complete;
    }
    fail(type_, "a type identifier is missing from the type mapping");
  }
  // An alias may name a plain identifier (a typedef of sequence<double>): keep it for element_of().
  const DDS_XTypes_CompleteTypeObject* resolve_alias(const DDS_XTypes_TypeIdentifier& id, int hops) const {
    if (id._d == DDS_XTypes_EK_COMPLETE) return resolve(id, hops);
    plain_alias_ = &id;
    return nullptr;
  }
  /// The identifier itself, or what an alias of a plain type stands for.
  const DDS_XTypes_TypeIdentifier& unaliased(const DDS_XTypes_TypeIdentifier& id) const {
    plain_alias_ = nullptr;
    const auto* to = resolve(id);
    if (to == nullptr && plain_alias_ != nullptr) return *plain_alias_;
    return id;
  }
  /// The element identifier of a sequence or array identifier (plain or by hash).
  const DDS_XTypes_TypeIdentifier* element_of(const DDS_XTypes_TypeIdentifier& raw) const {
    const auto& id = unaliased(raw);
    switch (id._d) {
      case DDS_XTypes_TI_PLAIN_SEQUENCE_SMALL:
        return id._u.seq_sdefn.element_identifier;
      case DDS_XTypes_TI_PLAIN_SEQUENCE_LARGE:
        return id._u.seq_ldefn.element_identifier;
      case DDS_XTypes_TI_PLAIN_ARRAY_SMALL:
        return id._u.array_sdefn.element_identifier;
      case DDS_XTypes_TI_PLAIN_ARRAY_LARGE:
        return id._u.array_ldefn.element_identifier;
      default:
        break;
    }
    if (const auto* to = resolve(id)) {
      if (to->_d == DDS_XTypes_TK_SEQUENCE) return &to->_u.sequence_type.element.common.type;
      if (to->_d == DDS_XTypes_TK_ARRAY) return &to->_u.array_type.element.common.type;
    }
    fail(type_, "a sequence or array member has no element type");
  }

  NodePtr structure(const std::uint32_t* ops, const DDS_XTypes_CompleteStructType& st, int depth) {
    const std::string name = st.header.detail.type_name;
    if (st.header.base_type._d != DDS_XTypes_TK_NONE) fail(name, "inheritance is not supported");
    auto node = std::make_shared<TypeNode>();
    node->kind = Kind::kStruct;
    std::size_t pc = 0;
    if (DDS_OP(ops[pc]) == DDS_OP_DLC) ++pc;  // @appendable: same memory layout
    if (DDS_OP(ops[pc]) == DDS_OP_PLC) fail(name, "@mutable types are not supported");
    std::uint32_t index = 0;
    while (DDS_OP(ops[pc]) != DDS_OP_RTS) {
      if (DDS_OP(ops[pc]) != DDS_OP_ADR) fail(name, "unexpected instruction in a struct");
      if (index >= st.member_seq._length) fail(name, "more fields in the ops than in the type object");
      const auto& m = st.member_seq._buffer[index++];
      std::size_t words = 0;
      Member member = adr(ops + pc, m.common.member_type_id, depth, words);
      member.name = m.detail.name;
      node->members.push_back(std::move(member));
      pc += words;
    }
    if (index != st.member_seq._length) fail(name, "fewer fields in the ops than in the type object");
    return node;
  }

  NodePtr union_type(const std::uint32_t* ops, const DDS_XTypes_CompleteUnionType& ut, int depth) {
    const std::string name = ut.header.detail.type_name;
    const std::uint32_t op = ops[0];
    if (DDS_OP(op) != DDS_OP_ADR || DDS_OP_TYPE(op) != DDS_OP_VAL_UNI) fail(name, "a union without a UNI instruction");
    auto node = std::make_shared<TypeNode>();
    node->kind = Kind::kUnion;
    node->discriminator_offset = ops[1];
    const std::uint32_t ncases = ops[2];
    const std::uint32_t cases_at = ops[3] & 0xffffu;
    const auto disc_code = static_cast<std::uint32_t>(DDS_OP_SUBTYPE(op));
    node->discriminator = scalar(disc_code, op, ut.discriminator.common.type_id);
    const bool has_default = (op & DDS_OP_FLAG_DEF) != 0;
    for (std::uint32_t k = 0; k < ncases; ++k) {
      const std::uint32_t* jeq = ops + cases_at + 4 * k;
      if (DDS_OP(jeq[0]) != DDS_OP_JEQ4) fail(name, "a union case without a JEQ4 instruction");
      UnionCase c;
      c.label = static_cast<std::int32_t>(jeq[1]);
      c.is_default = has_default && k + 1 == ncases;
      const DDS_XTypes_CompleteUnionMember* um = nullptr;
      for (std::uint32_t i = 0; i < ut.member_seq._length && um == nullptr; ++i) {
        const auto& cand = ut.member_seq._buffer[i];
        if (c.is_default) {
          if (cand.common.member_flags & DDS_XTypes_IS_DEFAULT) um = &cand;
          continue;
        }
        for (std::uint32_t l = 0; l < cand.common.label_seq._length; ++l)
          if (cand.common.label_seq._buffer[l] == c.label) um = &cand;
      }
      if (um == nullptr) fail(name, "a union case label missing from the type object");
      c.member.name = um->detail.name;
      c.member.offset = jeq[2];
      c.member.external = (jeq[0] & DDS_OP_FLAG_EXT) != 0;
      const auto code = static_cast<std::uint32_t>(DDS_JEQ_TYPE(jeq[0]));
      if (scalar_size(code) != 0 || code == DDS_OP_VAL_ENU) {
        c.member.type = scalar(code, jeq[0], um->common.type_id);
      } else if (code == DDS_OP_VAL_STR) {
        c.member.type = string_node();
      } else {
        const std::uint32_t* sub = jeq + DDS_OP_JUMP(jeq[0]);  // signed: cases may jump back to shared ops
        if (code == DDS_OP_VAL_STU || code == DDS_OP_VAL_UNI) {
          c.member.type = aggregate(sub, resolve(um->common.type_id), depth + 1);
        } else {
          std::size_t words = 0;
          c.member.type = adr(sub, um->common.type_id, depth + 1, words).type;
        }
      }
      node->cases.push_back(std::move(c));
    }
    return node;
  }

  static NodePtr string_node() {
    auto node = std::make_shared<TypeNode>();
    node->kind = Kind::kString;
    node->stride = sizeof(char*);
    return node;
  }

  /// A scalar of serializer type `code`: bool, integer, float, enum (names from its type object) or
  /// bitmask. `op` holds the flags.
  NodePtr scalar(std::uint32_t code, std::uint32_t op, const DDS_XTypes_TypeIdentifier& id) const {
    auto node = std::make_shared<TypeNode>();
    const std::uint32_t flags = DDS_OP_FLAGS(op);
    switch (code) {
      case DDS_OP_VAL_BLN:
        node->kind = Kind::kBool;
        node->size = 1;
        break;
      case DDS_OP_VAL_ENU:
      case DDS_OP_VAL_BMK: {
        node->kind = code == DDS_OP_VAL_ENU ? Kind::kEnum : Kind::kBitmask;
        node->size = DDS_OP_FLAGS_SZ(flags);
        if (code == DDS_OP_VAL_ENU) {
          const auto* to = resolve(id);
          if (to == nullptr || to->_d != DDS_XTypes_TK_ENUM) fail(type_, "an enum member without its enum type");
          const auto& lits = to->_u.enumerated_type.literal_seq;
          for (std::uint32_t i = 0; i < lits._length; ++i)
            node->names[lits._buffer[i].common.value] = lits._buffer[i].detail.name;
        }
        break;
      }
      default: {
        node->size = scalar_size(code);
        if (node->size == 0) fail(type_, "unsupported scalar type code " + std::to_string(code));
        // The identifier decides when it is a primitive (union cases and discriminators carry no FP
        // flag, and a discriminator's DEF flag is the FP bit); the instruction's flags otherwise.
        const auto& plain = unaliased(id);
        const bool primitive = plain._d >= DDS_XTypes_TK_BOOLEAN && plain._d <= DDS_XTypes_TK_CHAR16;
        const bool fp = primitive ? plain._d == DDS_XTypes_TK_FLOAT32 || plain._d == DDS_XTypes_TK_FLOAT64
                                  : (flags & DDS_OP_FLAG_FP) != 0;
        const bool sgn = primitive ? plain._d == DDS_XTypes_TK_INT16 || plain._d == DDS_XTypes_TK_INT32 ||
                                         plain._d == DDS_XTypes_TK_INT64 || plain._d == DDS_XTypes_TK_CHAR8
                                   : (flags & DDS_OP_FLAG_SGN) != 0;
        node->kind = fp ? Kind::kFloat : sgn ? Kind::kSigned : Kind::kUnsigned;
      }
    }
    node->stride = node->size;
    return node;
  }

  /// The element of a sequence or array instruction: `sub` the subtype, `extra` the words after the
  /// offset (and bound), `elem` the element's identifier.
  NodePtr element(const std::uint32_t* ops, std::uint32_t op, const std::uint32_t* extra, bool is_array,
                  const DDS_XTypes_TypeIdentifier& elem, int depth, std::size_t& words) {
    const auto sub = static_cast<std::uint32_t>(DDS_OP_SUBTYPE(op));
    const std::size_t base = static_cast<std::size_t>(extra - ops);
    if (scalar_size(sub) != 0) {
      words = base;
      return scalar(sub, op, elem);
    }
    switch (sub) {
      case DDS_OP_VAL_ENU:
        words = base + 1;
        return scalar(sub, op, elem);
      case DDS_OP_VAL_BMK:
        words = base + 2;
        return scalar(sub, op, elem);
      case DDS_OP_VAL_STR:
        words = base;
        return string_node();
      case DDS_OP_VAL_BST: {
        auto node = std::make_shared<TypeNode>();
        node->kind = Kind::kBoundedString;
        node->size = is_array ? extra[1] : extra[0];
        node->stride = node->size;
        words = base + (is_array ? 2 : 1);
        return node;
      }
      case DDS_OP_VAL_SEQ:
      case DDS_OP_VAL_BSQ:
      case DDS_OP_VAL_ARR:
      case DDS_OP_VAL_UNI:
      case DDS_OP_VAL_STU: {
        // sequence: [elem-size] [next-insn, elem-insn]; array: [next-insn, elem-insn] [elem-size]
        const std::uint32_t jumps = is_array ? extra[0] : extra[1];
        const std::uint32_t elem_size = is_array ? extra[1] : extra[0];
        words = DDS_OP_ADR_JMP(jumps);
        const std::uint32_t* sub_ops = ops + (jumps & 0xffffu);
        NodePtr node;
        if (sub == DDS_OP_VAL_UNI || sub == DDS_OP_VAL_STU) {
          node = aggregate(sub_ops, resolve(elem), depth + 1);
        } else {
          std::size_t w = 0;
          node = adr(sub_ops, elem, depth + 1, w).type;
        }
        auto copy = std::make_shared<TypeNode>(*node);
        copy->stride = elem_size;
        return copy;
      }
      default:
        fail(type_, "unsupported collection element type code " + std::to_string(sub));
    }
  }

  /// One ADR instruction at `ops` (a struct field, or a collection's element at offset 0). Sets `words`
  /// to the instruction's length.
  Member adr(const std::uint32_t* ops, const DDS_XTypes_TypeIdentifier& id, int depth, std::size_t& words) {
    if (depth > kMaxDepth) fail(type_, "nesting deeper than " + std::to_string(kMaxDepth));
    const std::uint32_t op = ops[0];
    if (DDS_OP(op) != DDS_OP_ADR) fail(type_, "expected a field instruction");
    if (op & DDS_OP_FLAG_BASE) fail(type_, "inheritance is not supported");
    Member m;
    m.offset = ops[1];
    m.external = (op & DDS_OP_FLAG_EXT) != 0;
    const auto code = static_cast<std::uint32_t>(DDS_OP_TYPE(op));
    switch (code) {
      case DDS_OP_VAL_1BY:
      case DDS_OP_VAL_2BY:
      case DDS_OP_VAL_4BY:
      case DDS_OP_VAL_8BY:
      case DDS_OP_VAL_BLN:
        words = 2;
        m.type = scalar(code, op, id);
        break;
      case DDS_OP_VAL_ENU:
        words = 3;
        m.type = scalar(code, op, id);
        break;
      case DDS_OP_VAL_BMK:
        words = 4;
        m.type = scalar(code, op, id);
        break;
      case DDS_OP_VAL_STR: {
        words = 2;
        auto node = std::make_shared<TypeNode>(*string_node());
        node->optional_string = (op & DDS_OP_FLAG_OPT) != 0;
        m.type = node;
        break;
      }
      case DDS_OP_VAL_BST: {
        words = 3;
        auto node = std::make_shared<TypeNode>();
        node->kind = Kind::kBoundedString;
        node->size = ops[2];
        node->stride = node->size;
        m.type = node;
        break;
      }
      case DDS_OP_VAL_SEQ:
      case DDS_OP_VAL_BSQ: {
        const auto* elem = element_of(id);
        auto node = std::make_shared<TypeNode>();
        node->kind = Kind::kSequence;
        node->element = element(ops, op, ops + (code == DDS_OP_VAL_BSQ ? 3 : 2), false, *elem, depth, words);
        m.type = node;
        break;
      }
      case DDS_OP_VAL_ARR: {
        const auto* elem = element_of(id);
        auto node = std::make_shared<TypeNode>();
        node->kind = Kind::kArray;
        node->count = ops[2];
        node->element = element(ops, op, ops + 3, true, *elem, depth, words);
        m.type = node;
        break;
      }
      case DDS_OP_VAL_EXT: {
        words = DDS_OP_ADR_JMP(ops[2]);
        m.type = aggregate(ops + DDS_OP_ADR_JSR(ops[2]), resolve(id), depth + 1);
        break;
      }
      case DDS_OP_VAL_UNI: {
        // a union inline at offset 0 (an element of a collection of unions)
        const auto* to = resolve(id);
        if (to == nullptr || to->_d != DDS_XTypes_TK_UNION) fail(type_, "a union field without its union type");
        m.type = union_type(ops, to->_u.union_type, depth + 1);
        words = DDS_OP_ADR_JMP(ops[3]);
        break;
      }
      default:
        fail(type_, "unsupported field type code " + std::to_string(code));
    }
    if (words == 0) fail(type_, "a zero-length instruction");
    return m;
  }

  const DDS_XTypes_TypeMapping& map_;
  std::string type_;
  mutable const DDS_XTypes_TypeIdentifier* plain_alias_ = nullptr;
};

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
  if ((descriptor.m_flagset & DDS_TOPIC_XTYPES_METADATA) == 0 || descriptor.type_mapping.sz == 0)
    fail(type_name_, "its descriptor carries no XTypes type information (idlc 0.10 or later emits it)");
  ddsi_sertype_cdr_data_t ser{descriptor.type_mapping.sz, const_cast<std::uint8_t*>(descriptor.type_mapping.data)};
  ddsi_typemap_t* map = ddsi_typemap_deser(&ser);
  if (map == nullptr) fail(type_name_, "its type mapping does not deserialize");
  struct Free {
    ddsi_typemap_t* map;
    ~Free() {
      ddsi_typemap_fini(map);
      dds_free(map);
    }
  } free_map{map};
  const auto& mapping = *reinterpret_cast<const DDS_XTypes_TypeMapping*>(map);
  Compiler compiler(mapping, type_name_);
  const auto* top = compiler.by_name(type_name_);
  if (top == nullptr) fail(type_name_, "the type mapping has no complete type object of that name");
  root_ = compiler.aggregate(descriptor.m_ops, top, 0);
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
