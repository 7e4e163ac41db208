#pragma once
/// @file
/// Reading and filling wire sequences (the `dds_sequence_*` structs idlc generates: _buffer, _length,
/// _maximum, _release) without touching their fields: outside common/dds and the protocol libraries no
/// code does (test/checks/wire_types.sh). Copies into std::vector and borrowed std::vector storage are
/// in conversions.hpp (to_vector, wire_sequence).

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include <dds/dds.h>

namespace rigger::dds {

/// The elements of a wire sequence as a read-only range: range-for, size(), data(), operator[]. Valid
/// while the sample it views is (a loaned sample: inside the take callback). A null buffer reads as
/// empty whatever its length says.
template <typename Seq>
class SequenceView {
 public:
  using Element = std::remove_pointer_t<decltype(Seq::_buffer)>;
  explicit SequenceView(const Seq& seq) : data_(seq._buffer), size_(seq._buffer == nullptr ? 0 : seq._length) {}
  const Element* begin() const { return data_; }
  const Element* end() const { return data_ + size_; }
  const Element* data() const { return data_; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const Element& operator[](std::size_t i) const { return data_[i]; }

 private:
  const Element* data_;
  std::size_t size_;
};

/// `for (const auto& e : dds::elements(reply.entries))`.
template <typename Seq>
SequenceView<Seq> elements(const Seq& seq) {
  return SequenceView<Seq>(seq);
}

/// Borrows `count` elements at `data` (a buffer the caller owns and keeps unchanged until the write: an
/// image, a byte string) for a wire sequence field, which does not release it.
template <typename Seq>
void wire_buffer(Seq& seq, std::remove_pointer_t<decltype(Seq::_buffer)>* data, std::size_t count) {
  seq._buffer = data;
  seq._length = static_cast<std::uint32_t>(count);
  seq._maximum = static_cast<std::uint32_t>(count);
  seq._release = false;
}

/// Gives a wire sequence `count` zeroed elements of its own (dds_alloc), released with the sample
/// (dds_sample_free): for samples built to be kept, not borrowed. Returns the elements to fill.
template <typename Seq>
std::remove_pointer_t<decltype(Seq::_buffer)>* alloc_sequence(Seq& seq, std::size_t count) {
  using Element = std::remove_pointer_t<decltype(Seq::_buffer)>;
  seq._length = seq._maximum = static_cast<std::uint32_t>(count);
  seq._release = true;
  seq._buffer = count == 0 ? nullptr : static_cast<Element*>(dds_alloc(count * sizeof(Element)));
  return seq._buffer;
}

}  // namespace rigger::dds
