// The decoded size of a filtered HDF5 chunk (hdf5_chunk_filters.hpp).
#include "io/hdf5_chunk_filters.hpp"

#include <zlib.h>

#include <limits>
#include <stdexcept>

namespace celc::detail {
namespace {

constexpr int kDeflate = 1, kShuffle = 2, kFletcher32 = 3, kBlosc = 32001;

std::uint32_t littleEndian32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

/// Inflates the zlib stream `in` into `out`, at most `limit` bytes; returns
/// the bytes it holds, or `limit` when it holds at least that many.
std::uint64_t inflatedBytes(const unsigned char* in, std::uint64_t in_bytes, std::uint64_t limit,
                            std::vector<unsigned char>& out) {
  if (in_bytes > std::numeric_limits<uInt>::max() || limit > std::numeric_limits<uInt>::max())
    throw std::runtime_error("a deflate chunk above 4 GB");
  out.resize(std::size_t(limit));
  z_stream z{};
  if (inflateInit(&z) != Z_OK) throw std::runtime_error("zlib cannot start inflating");
  z.next_in = const_cast<unsigned char*>(in);
  z.avail_in = uInt(in_bytes);
  z.next_out = out.data();
  z.avail_out = uInt(limit);
  const int status = inflate(&z, Z_FINISH);
  const std::uint64_t produced = z.total_out;
  inflateEnd(&z);
  if (status == Z_STREAM_END) return produced;
  if (produced >= limit) return limit;  // more than the caller asked about
  // Z_BUF_ERROR with output room left: the input ran out before the stream's end
  throw std::runtime_error(status == Z_BUF_ERROR ? "a deflate stream that ends before its data does"
                                                 : "a damaged deflate stream");
}

}  // namespace

bool hdf5FilterSizeKnown(int filter_id) {
  return filter_id == kDeflate || filter_id == kShuffle || filter_id == kFletcher32 || filter_id == kBlosc;
}

std::uint64_t decodedChunkBytes(const std::vector<int>& filters, std::uint32_t skipped_mask,
                                const std::vector<unsigned char>& stored, std::uint64_t expected,
                                std::vector<unsigned char>& scratch) {
  // The bytes at each step are `stored` (a prefix of it) until deflate has
  // decoded them into `scratch`; blosc gives a size but no bytes.
  const unsigned char* bytes = stored.data();
  std::uint64_t size = stored.size();
  bool bytes_known = true;
  for (std::size_t k = filters.size(); k-- > 0;) {
    if (k < 32 && (skipped_mask >> k & 1u)) continue;
    const int id = filters[k];
    if (id == kShuffle) continue;
    if (id == kFletcher32) {
      if (size < 4) throw std::runtime_error("a fletcher32 chunk shorter than its 4-byte checksum");
      size -= 4;
      continue;
    }
    if (!bytes_known)
      throw std::runtime_error("filter " + std::to_string(id) + " after blosc: its decoded size cannot be found");
    if (id == kDeflate) {
      size = inflatedBytes(bytes, size, expected + 1, scratch);
      bytes = scratch.data();
    } else if (id == kBlosc) {
      if (size < 16) throw std::runtime_error("a blosc chunk shorter than its 16-byte header");
      if (littleEndian32(bytes + 12) > size)
        throw std::runtime_error("a blosc header that claims " + std::to_string(littleEndian32(bytes + 12)) +
                                 " stored bytes in a chunk of " + std::to_string(size));
      size = littleEndian32(bytes + 4);
      bytes_known = false;
    } else {
      throw std::runtime_error("filter " + std::to_string(id) + ": its decoded size cannot be found");
    }
  }
  return size;
}

}  // namespace celc::detail
