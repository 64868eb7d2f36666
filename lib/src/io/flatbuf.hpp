#pragma once
// Private: a minimal read-only FlatBuffers decoder that checks every offset and
// length against the buffer before use (the AEDAT 4.0 payloads are small tables).
// Layout facts: a table starts with an int32 soffset to its vtable
// (vtable = table - soffset); the vtable holds uint16 vtable size, uint16 table
// size, then one uint16 offset per field (0 = absent). Offsets to sub-objects are
// uint32, relative to where they are stored; vectors and strings start with a
// uint32 element count.
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

namespace celc::detail {

struct FbError : std::runtime_error {
  FbError(std::size_t at, const std::string& what) : std::runtime_error(what), offset(at) {}
  std::size_t offset;
};

class FbBuf {
 public:
  FbBuf(const unsigned char* data, std::size_t size) : d_(data), n_(size) {}
  std::size_t size() const { return n_; }
  const unsigned char* data() const { return d_; }

  void need(std::size_t at, std::size_t len, const char* what) const {
    if (at > n_ || len > n_ - at)
      throw FbError(at, std::string("flatbuffer ") + what + " out of bounds (" + std::to_string(len) +
                            " bytes at " + std::to_string(at) + ", buffer " + std::to_string(n_) + ")");
  }
  template <typename T>
  T get(std::size_t at) const {
    need(at, sizeof(T), "scalar");
    T v;
    std::memcpy(&v, d_ + at, sizeof(T));
    return v;
  }
  /// Position of the object a uoffset stored at `at` points to.
  std::size_t deref(std::size_t at) const {
    const auto off = get<std::uint32_t>(at);
    if (off == 0) throw FbError(at, "flatbuffer zero offset");
    const std::size_t target = at + off;
    need(target, 4, "offset target");
    return target;
  }

  struct Table {
    std::size_t pos = 0, vt = 0;
    std::uint16_t vt_size = 0, tb_size = 0;
  };
  Table table(std::size_t pos) const {
    Table t;
    t.pos = pos;
    const auto so = get<std::int32_t>(pos);
    const std::int64_t vt = std::int64_t(pos) - std::int64_t(so);
    if (vt < 0 || std::uint64_t(vt) + 4 > n_) throw FbError(pos, "flatbuffer vtable out of bounds");
    t.vt = std::size_t(vt);
    t.vt_size = get<std::uint16_t>(t.vt);
    t.tb_size = get<std::uint16_t>(t.vt + 2);
    if (t.vt_size < 4 || (t.vt_size & 1u)) throw FbError(t.vt, "flatbuffer vtable size invalid");
    need(t.vt, t.vt_size, "vtable");
    need(pos, t.tb_size, "table");
    return t;
  }
  /// Absolute position of field `i`, or 0 when absent.
  std::size_t field(const Table& t, int i, std::size_t width) const {
    const std::size_t slot = 4 + 2 * std::size_t(i);
    if (slot + 2 > t.vt_size) return 0;
    const auto off = get<std::uint16_t>(t.vt + slot);
    if (off == 0) return 0;
    if (off < 4 || std::size_t(off) + width > t.tb_size)
      throw FbError(t.vt + slot, "flatbuffer field outside its table");
    return t.pos + off;
  }
  template <typename T>
  T scalar(const Table& t, int i, T dflt) const {
    const std::size_t at = field(t, i, sizeof(T));
    return at ? get<T>(at) : dflt;
  }
  /// Vector field: position of the first element and the count (0/0 when absent).
  bool vector(const Table& t, int i, std::size_t elem_size, std::size_t& first, std::size_t& count) const {
    const std::size_t at = field(t, i, 4);
    if (!at) return false;
    const std::size_t v = deref(at);
    const auto len = get<std::uint32_t>(v);
    first = v + 4;
    count = len;
    if (elem_size && std::uint64_t(len) * elem_size > n_ - first)
      throw FbError(v, "flatbuffer vector of " + std::to_string(len) + " elements exceeds the buffer");
    return true;
  }
  std::string string(const Table& t, int i) const {
    std::size_t first, count;
    if (!vector(t, i, 1, first, count)) return {};
    return std::string(reinterpret_cast<const char*>(d_ + first), count);
  }
  /// Root table of a buffer, with optional 4-character identifier check; handles
  /// size-prefixed buffers when `size_prefixed`.
  Table root(bool size_prefixed, const char* ident) const {
    std::size_t base = 0;
    if (size_prefixed) {
      const auto sz = get<std::uint32_t>(0);
      if (std::uint64_t(sz) + 4 > n_) throw FbError(0, "flatbuffer size prefix exceeds the buffer");
      base = 4;
    }
    if (ident) {
      need(base + 4, 4, "identifier");
      if (std::memcmp(d_ + base + 4, ident, 4) != 0)
        throw FbError(base + 4, std::string("flatbuffer identifier is not '") + ident + "'");
    }
    return table(deref(base));
  }

 private:
  const unsigned char* d_;
  std::size_t n_;
};

}  // namespace celc::detail
