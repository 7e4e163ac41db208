// The compiled type of a topic: the descriptor's ops walked together with its XTypes type objects.
#include "sample_type.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

#include <dds/ddsi/ddsi_sertype.h>
#include <dds/ddsi/ddsi_typelib.h>
#include <dds/ddsi/ddsi_xt_typeinfo.h>
#include <dds/ddsi/ddsi_xt_typemap.h>

namespace rigger::dds {
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

}  // namespace

NodePtr compile_sample_type(const dds_topic_descriptor_t& descriptor, const std::string& type_name) {
  if ((descriptor.m_flagset & DDS_TOPIC_XTYPES_METADATA) == 0 || descriptor.type_mapping.sz == 0)
    fail(type_name, "its descriptor carries no XTypes type information (idlc 0.10 or later emits it)");
  ddsi_sertype_cdr_data_t ser{descriptor.type_mapping.sz, const_cast<std::uint8_t*>(descriptor.type_mapping.data)};
  ddsi_typemap_t* map = ddsi_typemap_deser(&ser);
  if (map == nullptr) fail(type_name, "its type mapping does not deserialize");
  struct Free {
    ddsi_typemap_t* map;
    ~Free() {
      ddsi_typemap_fini(map);
      dds_free(map);
    }
  } free_map{map};
  const auto& mapping = *reinterpret_cast<const DDS_XTypes_TypeMapping*>(map);
  Compiler compiler(mapping, type_name);
  const auto* top = compiler.by_name(type_name);
  if (top == nullptr) fail(type_name, "the type mapping has no complete type object of that name");
  return compiler.aggregate(descriptor.m_ops, top, 0);
}

}  // namespace rigger::dds
