// Warm-start keys of constraint rows: one 64-bit key per row, the emitting source's id in the top
// 16 bits and the source's own fields (element, point, object, sub-row) below it, each in a bit
// range of fixed width. Every key is packed here, each field checked against its width, so two
// different rows of a world never share a key (the layouts are in constraints/row_key_layouts.h).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace taut {

constexpr int kRowKeySourceBits = 16;   // source id: bits 48-63 of every key
constexpr int kRowKeyPayloadBits = 48;  // the source's fields: bits 0-47

// Source id of a row key.
inline int RowKeySource(std::uint64_t key) { return static_cast<int>(key >> kRowKeyPayloadBits); }

// The bits of a row key below the source id: the source's packed fields.
inline std::uint64_t RowKeyPayload(std::uint64_t key) {
  return key & ((std::uint64_t{1} << kRowKeyPayloadBits) - 1);
}

// One field of a key: its name (for error messages) and its width in bits.
struct RowKeyField {
  const char* name;
  int bits;
};

// The fields of one kind of source's keys, packed from the most significant (first field) to the
// least significant (last field) bits of the payload.
template <std::size_t N>
struct RowKeyLayout {
  const char* source;  // what emits the rows, for error messages
  std::array<RowKeyField, N> fields;

  // Total width of the fields (at most kRowKeyPayloadBits for a valid layout).
  constexpr int bits() const {
    int sum = 0;
    for (const RowKeyField& field : fields) sum += field.bits;
    return sum;
  }
};

namespace internal {
// Throws InputError unless 0 <= value < 2^bits, naming the source, the field, the value and the
// width.
void CheckRowKeyField(const char* source, const char* field, int bits, std::int64_t value);

// An integer as a field value (unsigned values beyond int64 saturate: they fit no field).
template <typename T>
std::int64_t AsRowKeyFieldValue(T value) {
  static_assert(std::is_integral_v<T>, "row key fields are integers");
  if constexpr (std::is_unsigned_v<T>) {
    constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
    return static_cast<std::int64_t>(std::min<std::uint64_t>(value, kMax));
  } else {
    return static_cast<std::int64_t>(value);
  }
}
}  // namespace internal

// The payload of the field values (one per field of `layout`, in its order). Throws InputError
// naming the field when a value does not fit its width.
template <std::size_t N>
std::uint64_t PackRowKeyPayload(const RowKeyLayout<N>& layout,
                                const std::array<std::int64_t, N>& values) {
  std::uint64_t payload = 0;
  for (std::size_t f = 0; f < N; ++f) {
    const RowKeyField& field = layout.fields[f];
    internal::CheckRowKeyField(layout.source, field.name, field.bits, values[f]);
    payload = payload << field.bits | static_cast<std::uint64_t>(values[f]);
  }
  return payload;
}

// The field values of a payload (inverse of PackRowKeyPayload).
template <std::size_t N>
std::array<std::int64_t, N> UnpackRowKeyPayload(const RowKeyLayout<N>& layout,
                                                std::uint64_t payload) {
  std::array<std::int64_t, N> values{};
  for (std::size_t f = N; f-- > 0;) {
    const int bits = layout.fields[f].bits;
    values[f] = static_cast<std::int64_t>(payload & ((std::uint64_t{1} << bits) - 1));
    payload >>= bits;
  }
  return values;
}

// The keys of one row source: its id, checked once here, and the layout of its fields.
template <std::size_t N>
class RowKeyPacker {
 public:
  // Throws InputError unless 0 <= source_id < 2^16.
  RowKeyPacker(const RowKeyLayout<N>& layout, int source_id)
      : layout_(layout), source_id_(source_id) {
    internal::CheckRowKeyField(layout.source, "source id", kRowKeySourceBits, source_id);
  }

  int source_id() const { return source_id_; }
  // The key of the row with these field values (layout order); throws InputError naming the
  // field when a value does not fit its width.
  std::uint64_t PackFields(const std::array<std::int64_t, N>& values) const {
    return static_cast<std::uint64_t>(source_id_) << kRowKeyPayloadBits |
           PackRowKeyPayload(layout_, values);
  }
  // As PackFields, one integer argument per field.
  template <typename... Values>
  std::uint64_t Pack(Values... values) const {
    static_assert(sizeof...(Values) == N, "one value per field of the layout");
    return PackFields({internal::AsRowKeyFieldValue(values)...});
  }
  // True when `key` carries this source's id.
  bool Owns(std::uint64_t key) const { return RowKeySource(key) == source_id_; }
  // The field values of a key of this source (inverse of Pack).
  std::array<std::int64_t, N> Unpack(std::uint64_t key) const {
    return UnpackRowKeyPayload(layout_, RowKeyPayload(key));
  }

 private:
  RowKeyLayout<N> layout_;
  int source_id_;
};

}  // namespace taut
