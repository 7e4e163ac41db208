#pragma once
/// @file
/// Any sample of any idlc-generated type as JSON or as readable text, for tools that work on every topic
/// (`riggerctl echo`). The memory layout comes from the descriptor's serializer program (`m_ops`, the
/// DDS_OP_* opcodes of dds/ddsc/dds_opcodes.h); the field and enumerator names from the XTypes type
/// information that idlc 0.10 embeds in every descriptor (`type_mapping`, the COMPLETE type objects) —
/// 0.10's idlc leaves the XML `m_meta` empty.
///
///   const dds::SampleFormat format(rigger_crane_CraneState_desc);
///   std::string line = format.to_json(&sample);          // {"header":{"stamp":{"sec":…},…},"mode":"…",…}
///
/// JSON: field names exactly as in the IDL, enums as their enumerator names, nested structs as objects,
/// sequences and arrays as arrays, strings as strings, booleans, numbers (floats that are NaN or infinite
/// as null), an unset @optional member as null, a union as {"<discriminator name>": value, "<case name>":
/// value}. Output is bounded (FormatLimits): a sequence or array longer than max_elements becomes
/// {"length": N, "first": [the first max_elements]}, a string longer than max_string is cut and ends in
/// "…"; nesting deeper than max_depth throws at construction.
///
/// Not supported (construction throws std::invalid_argument, naming the construct): @mutable types,
/// inheritance, maps, bitsets. char and int8 are indistinguishable in 0.10's type information and are
/// printed as numbers.

#include <cstddef>
#include <memory>
#include <string>

#include <dds/dds.h>

namespace rigger::dds {

/// Bounds on what one sample prints.
struct FormatLimits {
  std::size_t max_elements = 64;   ///< elements shown per sequence/array
  std::size_t max_string = 1024;   ///< bytes shown per string
  std::size_t max_output = 65536;  ///< about this many bytes per sample: past it the remaining sequences show
                                   ///< only their length and strings are cut; JSON then gets "truncated": true
                                   ///< at the top level, the text form a closing "… (cut at N bytes)" line
};

struct TypeNode;  // the compiled type, private to src/sample_type.hpp

/// The compiled layout and names of one type. Immutable after construction: thread-safe to share.
class SampleFormat {
 public:
  /// @throws std::invalid_argument when the descriptor carries no XTypes type information, uses an
  ///         unsupported construct, or its ops and type objects disagree.
  explicit SampleFormat(const dds_topic_descriptor_t& descriptor);
  ~SampleFormat();
  SampleFormat(SampleFormat&&) noexcept;
  SampleFormat& operator=(SampleFormat&&) noexcept;

  /// One line of JSON for `sample` (a pointer to the C struct of this descriptor's type). Never throws
  /// but std::bad_alloc.
  std::string to_json(const void* sample, const FormatLimits& limits = {}) const;
  /// A readable, indented form ("name: value" per line, nested structs indented by two spaces, short
  /// arrays of scalars on one line, as `ros2 topic echo` shows a message), ending in a newline.
  std::string to_text(const void* sample, const FormatLimits& limits = {}) const;
  /// The IDL type name, "rigger::crane::CraneState".
  const std::string& type_name() const { return type_name_; }

 private:
  std::string type_name_;
  std::shared_ptr<const TypeNode> root_;
};

}  // namespace rigger::dds
