#pragma once
// Internal: the compiled type of a topic, what SampleFormat's walk over a sample needs (sample_json.cpp),
// built once from the descriptor's ops and XTypes type objects (sample_type.cpp).

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <dds/dds.h>

#include "rigger/dds/sample_json.hpp"

namespace rigger::dds {

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

/// Compiles the type of `descriptor` (named `type_name`). @throws std::invalid_argument, naming the
/// construct, when the type cannot be formatted (see SampleFormat).
NodePtr compile_sample_type(const dds_topic_descriptor_t& descriptor, const std::string& type_name);

}  // namespace rigger::dds
