#pragma once
// The size a compressed HDF5 chunk decodes to, found before the HDF5 C
// library decodes it. The library (1.10.8) decodes a filtered chunk into a
// buffer of the decoded size and then copies the chunk's full size out of it:
// a chunk whose stream decodes to fewer bytes than its layout declares (a
// damaged layout or stream) is read beyond the library's buffer (found by the
// hdf5 fuzz target: 64 bytes decoded, 120 copied). The reader therefore
// decodes each stored chunk's size itself, through the filters it knows,
// before the library reads the chunk.
//
// Format facts: a dataset's filters are applied in pipeline order when
// written and in reverse order when read; bit i of a chunk's filter mask
// says filter i was skipped for that chunk. deflate (id 1) is a zlib stream;
// shuffle (2) keeps the size; fletcher32 (3) appends a 4-byte checksum;
// blosc (32001) starts with a 16-byte header whose bytes 4-7 hold the
// decoded size and bytes 12-15 the stored size (little-endian u32).
#include <cstdint>
#include <string>
#include <vector>

namespace celc::detail {

/// True for the filters whose decoded size `decodedChunkBytes` can find.
bool hdf5FilterSizeKnown(int filter_id);

/// The size [bytes] the stored chunk `stored` decodes to through `filters`
/// (filter ids in pipeline order) with filter i skipped where bit i of
/// `skipped_mask` is set. Decoding stops one byte past `expected`: a larger
/// answer means "more than expected". `scratch` is reused between calls.
/// Throws std::runtime_error saying what is damaged (a deflate stream that
/// does not end, a blosc header shorter than 16 bytes, ...), or naming a
/// filter `hdf5FilterSizeKnown` refuses.
std::uint64_t decodedChunkBytes(const std::vector<int>& filters, std::uint32_t skipped_mask,
                                const std::vector<unsigned char>& stored, std::uint64_t expected,
                                std::vector<unsigned char>& scratch);

}  // namespace celc::detail
