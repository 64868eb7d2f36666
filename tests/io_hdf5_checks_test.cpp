// HDF5 files written here (libhdf5, tests/fixtures/h5_writer.hpp) and then
// damaged byte by byte, or holding types and values the DSEC and MVSEC readers
// refuse: what the readers check before the HDF5 library reads (the inputs
// the fuzzer found among them). No shared fixture: they also run under the
// sanitizers (scripts/test_sanitize.sh --subset).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <vector>

#include "celc/io/event_reader.hpp"
#include "h5_writer.hpp"
#include "io/hdf5_chunk_filters.hpp"
#include "io_test_util.hpp"

using namespace celc;
using celc::test::patchBytes;
using celc::test::TempDir;

namespace {

/// `n` values first, first + step, ... of type T.
template <class T>
std::vector<T> range(std::size_t n, T first = T(0), T step = T(1)) {
  std::vector<T> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = T(first + T(i) * step);
  return v;
}
/// MVSEC events, n x 4 doubles: x = y = 0, t = t0 + i dt, polarity 1.
std::vector<double> mvsecEvents(std::size_t n, double t0, double dt) {
  std::vector<double> ev(n * 4, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    ev[4 * i + 2] = t0 + double(i) * dt;
    ev[4 * i + 3] = 1.0;
  }
  return ev;
}

/// A DSEC file of 60 events written by libhdf5, /events/x = 0, 1, ... + x0
/// stored as `x_storage` (y = 0, t = 0..59 us, p = 1); returns the stored
/// size of /events/x's chunk 0 when it is chunked, else 0.
unsigned long long writeDsecStoringX(const std::string& path, std::uint16_t x0,
                                     const celc::test::h5::DatasetOptions& x_storage) {
  const std::size_t n = 60;
  celc::test::h5::File f(path);
  f.write("events/x", range<std::uint16_t>(n, x0), {}, x_storage);
  f.write("events/y", std::vector<std::uint16_t>(n, 0));
  f.write("events/t", range<std::uint32_t>(n));
  f.write("events/p", std::vector<std::uint8_t>(n, 1));
  return x_storage.chunks.empty() ? 0 : f.chunkStoredSize("events/x", 0);
}

/// gzip (level 4) chunks of 32 values.
celc::test::h5::DatasetOptions gzipChunksOf32() {
  celc::test::h5::DatasetOptions gzip;
  gzip.chunks = {32};
  gzip.gzip = 4;
  return gzip;
}

}  // namespace

// ---- found by fuzz_hdf5: a chunk layout that disagrees with its stored chunks -------

TEST(IoRobustness, Hdf5ChunkLayoutLargerThanItsStoredChunksIsAnError) {
  // An MVSEC file whose events are stored in unfiltered chunks of 16 x 4 doubles
  // (512 bytes each), written by libhdf5; then the layout message's chunk rows
  // 16 -> 199 (the fuzzer's change): unchecked, the HDF5 library copies 6368 bytes
  // out of each 512-byte chunk buffer (a heap overflow inside libhdf5).
  TempDir d;
  const std::string h5 = d.file("m.h5");
  {
    celc::test::h5::File f(h5);
    celc::test::h5::DatasetOptions chunked;
    chunked.chunks = {16, 4};
    f.write("davis/left/events", mvsecEvents(60, 1.0, 1e-5), {60, 4}, chunked);
  }
  EXPECT_EQ(celc::test::drain(h5), 60u);  // the file as written reads
  // the layout message's dimensions: chunk rows, columns, then the element size (uint32 each)
  ASSERT_TRUE(patchBytes(h5, std::string("\x10\x00\x00\x00\x04\x00\x00\x00\x08\x00\x00\x00", 12), 0, "\xC7"));
  EXPECT_IO_ERROR(celc::test::drain(h5), "m.h5: dataset /davis/left/events: chunk 0 at byte",
                  "holds 512 bytes, an unfiltered chunk of its layout 6368 (damaged file)");
}

TEST(IoRobustness, Hdf5CompactDataShorterThanItsDatasetIsAnError) {
  // A DSEC file whose /events/x is stored compact (in its object header, 60
  // uint16 = 120 bytes), written by libhdf5; then the layout message's compact size
  // 120 -> 0 (the fuzzer turned a chunked layout into a compact one of no
  // bytes): unchecked, the HDF5 library copies the values from a null buffer.
  TempDir d;
  const std::string h5 = d.file("c.h5");
  celc::test::h5::DatasetOptions compact;
  compact.compact = true;
  writeDsecStoringX(h5, 0x4100, compact);
  EXPECT_EQ(celc::test::drain(h5), 60u);  // the file as written reads
  // the compact layout message: version 3, class 0, size 120 (uint16), then x = 0x4100, 0x4101, ...
  ASSERT_TRUE(patchBytes(h5, std::string("\x03\x00\x78\x00\x00\x41\x01\x41", 8), 2, std::string(1, '\0')));
  EXPECT_IO_ERROR(celc::test::drain(h5), "c.h5: dataset /events/x: compact data of 0 bytes for 120 bytes of values",
                  "(damaged file)");
}

TEST(IoRobustness, Hdf5CompressedChunkLargerThanTheFileIsAnError) {
  // A DSEC file whose /events/x is stored in gzip chunks of 32 values, written
  // by libhdf5; then the chunk index's stored size of chunk 0 (a uint32 followed
  // by the filter mask and the chunk's offsets, all 0) -> 0x745F0000 (found by
  // the CI fuzz run): the HDF5 library allocated 1.9 GB to read it.
  TempDir d;
  const std::string h5 = d.file("z.h5");
  const unsigned long long size = writeDsecStoringX(h5, 0, gzipChunksOf32());
  // the chunk index entry: stored size, filter mask 0, offsets 0 (two uint64)
  std::string key(24, '\0');
  const auto size32 = std::uint32_t(size);
  std::memcpy(&key[0], &size32, 4);
  ASSERT_TRUE(patchBytes(h5, key, 0, std::string("\x00\x00\x5F\x74", 4)));
  EXPECT_IO_ERROR(celc::test::drain(h5), "z.h5: dataset /events/x: compressed chunk 0 at byte",
                  "claims 1952382976 bytes, more than the file's");
}

TEST(IoRobustness, Hdf5CompressedChunkShorterThanItsLayoutIsAnError) {
  // A DSEC file whose /events/x is stored in gzip chunks of 32 uint16 (64
  // bytes decoded), written by libhdf5; then the layout message's chunk rows
  // 32 -> 2080 (the CI fuzz run's change): unchecked, the HDF5 library inflates
  // 64 bytes and copies 120 out of them (a heap overflow inside libhdf5).
  TempDir d;
  const std::string h5 = d.file("s.h5");
  writeDsecStoringX(h5, 0, gzipChunksOf32());
  EXPECT_EQ(celc::test::drain(h5), 60u);  // the file as written reads
  // the layout message's dimensions: chunk rows, then the element size (uint32 each)
  ASSERT_TRUE(patchBytes(h5, std::string("\x20\x00\x00\x00\x02\x00\x00\x00", 8), 1, "\x08"));
  EXPECT_IO_ERROR(celc::test::drain(h5), "s.h5: dataset /events/x: the chunk at row 0 decodes to 64 bytes",
                  "its layout's 4160 (damaged file)");
}

namespace {

/// `bytes` as a zlib stream of one stored (uncompressed) deflate block.
std::vector<unsigned char> storedZlib(const std::vector<unsigned char>& bytes) {
  const auto n = std::uint16_t(bytes.size());
  // zlib header (deflate, 32 KB window), a final stored block, its length and the length's complement
  std::vector<unsigned char> z = {0x78, 0x01, 0x01};
  for (std::uint16_t v : {n, std::uint16_t(~n)}) {
    z.push_back(std::uint8_t(v));
    z.push_back(std::uint8_t(v >> 8));
  }
  for (unsigned char c : bytes) z.push_back(c);
  std::uint32_t a = 1, b = 0;  // Adler-32, big-endian after the data
  for (unsigned char c : bytes) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  const std::uint32_t adler = b << 16 | a;
  for (int shift : {24, 16, 8, 0}) z.push_back(std::uint8_t(adler >> shift));
  return z;
}

}  // namespace

TEST(IoHdf5ChunkFilters, DecodedSizeThroughDeflateShuffleFletcherAndBlosc) {
  using celc::detail::decodedChunkBytes;
  std::vector<unsigned char> scratch;
  const std::vector<unsigned char> values(64, 7);
  const std::vector<unsigned char> deflated = storedZlib(values);
  // deflate alone, then with shuffle before it (size kept) and fletcher32 after it (4 bytes dropped)
  EXPECT_EQ(decodedChunkBytes({1}, 0, deflated, 64, scratch), 64u);
  EXPECT_EQ(decodedChunkBytes({1}, 0, deflated, 4160, scratch), 64u);  // the fuzzer's chunk: fewer than the layout's
  EXPECT_EQ(decodedChunkBytes({1}, 0, deflated, 32, scratch), 33u);    // more than expected stops one byte past it
  std::vector<unsigned char> with_checksum = deflated;
  with_checksum.insert(with_checksum.end(), {1, 2, 3, 4});
  EXPECT_EQ(decodedChunkBytes({2, 1, 3}, 0, with_checksum, 64, scratch), 64u);
  // a skipped filter (bit i of the mask) is not decoded: the stored bytes are the values
  EXPECT_EQ(decodedChunkBytes({1}, 1u, values, 64, scratch), 64u);
  // blosc: its header's decoded size (bytes 4-7); its stored size (bytes 12-15) must fit the chunk
  std::vector<unsigned char> blosc(40, 0);
  blosc[4] = 0x40;   // 64 decoded bytes
  blosc[12] = 40;    // 40 stored bytes
  EXPECT_EQ(decodedChunkBytes({32001}, 0, blosc, 64, scratch), 64u);
  blosc[12] = 41;
  EXPECT_THROW(decodedChunkBytes({32001}, 0, blosc, 64, scratch), std::runtime_error);
  // damaged or unknown: a cut deflate stream, a bad check value, a short blosc header, szip
  const std::vector<unsigned char> cut(deflated.begin(), deflated.begin() + 30);
  EXPECT_THROW(decodedChunkBytes({1}, 0, cut, 64, scratch), std::runtime_error);
  std::vector<unsigned char> bad_check = deflated;
  bad_check.back() ^= 1;
  EXPECT_THROW(decodedChunkBytes({1}, 0, bad_check, 64, scratch), std::runtime_error);
  EXPECT_THROW(decodedChunkBytes({32001}, 0, std::vector<unsigned char>(15, 0), 64, scratch), std::runtime_error);
  EXPECT_THROW(decodedChunkBytes({4}, 0, values, 64, scratch), std::runtime_error);
  EXPECT_FALSE(celc::detail::hdf5FilterSizeKnown(4));
  EXPECT_TRUE(celc::detail::hdf5FilterSizeKnown(32001));
}

// ---- HDF5: dataset types and values checked as stored ----------------------------

namespace {

// One DSEC column: writes its values into the named dataset.
using Column = std::function<void(celc::test::h5::File&, const std::string&)>;
template <class T>
Column column(std::vector<T> values) {
  return [values](celc::test::h5::File& f, const std::string& name) { f.write(name, values); };
}
const Column kX = column(range<std::uint16_t>(6)), kY = column(range<std::int32_t>(6)),
             kT = column(range<std::int64_t>(6, 0, 10)), kP = column(std::vector<std::uint8_t>{0, 1, 1, 0, 1, 0});
void writeDsec(const std::string& path, const Column& x, const Column& y, const Column& t, const Column& p) {
  celc::test::h5::File f(path);
  x(f, "events/x");
  y(f, "events/y");
  t(f, "events/t");
  p(f, "events/p");
}

}  // namespace

TEST(IoRobustness, Hdf5DatasetTypesAndValuesAreCheckedBeforeConversion) {
  TempDir d;
  writeDsec(d.file("ok.h5"), kX, kY, kT, kP);
  {
    auto r = openEventSource(d.file("ok.h5"));
    const auto ev = readAllEvents(*r);
    ASSERT_EQ(ev.size(), 6u);
    EXPECT_EQ(ev[5].y, 5.0f);
    EXPECT_DOUBLE_EQ(ev[5].t, 50e-6);
    EXPECT_TRUE(ev[1].on);
    EXPECT_FALSE(ev[3].on);
  }
}

// A file the readers refuse: its name, how it is written, whether opening it
// (a dataset's type) or reading it (a value) fails, and the message's fragments.
struct Hdf5Refusal {
  const char* label;
  const char* file;
  std::function<void(const std::string& path)> write;
  bool on_open;
  std::vector<std::string> fragments;
};
class IoRobustnessHdf5Types : public ::testing::TestWithParam<Hdf5Refusal> {};

TEST_P(IoRobustnessHdf5Types, Hdf5DatasetTypesAndValuesAreCheckedBeforeConversion) {
  TempDir d;
  const Hdf5Refusal& c = GetParam();
  c.write(d.file(c.file));
  if (c.on_open) {
    EXPECT_IO_ERROR(openEventSource(d.file(c.file)), c.fragments);
  } else {
    EXPECT_IO_ERROR(celc::test::drain(d.file(c.file)), c.fragments);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Datasets, IoRobustnessHdf5Types,
    ::testing::Values(
        Hdf5Refusal{"t_float64_seconds", "tf.h5",
                    [](const std::string& f) { writeDsec(f, kX, kY, column(range<double>(6, 0.0, 0.01)), kP); }, true,
                    {"tf.h5: dataset /events/t: type float64, expected integers", "microseconds as integers"}},
        Hdf5Refusal{"y_negative", "yn.h5",
                    [](const std::string& f) {
                      writeDsec(f, kX, column(std::vector<std::int32_t>{0, 1, 2, -5, 4, 5}), kT, kP);
                    },
                    false, {"yn.h5: dataset /events/y: row 3: value -5 outside [0, 65535]"}},
        Hdf5Refusal{"y_beyond_uint16", "yb.h5",
                    [](const std::string& f) {
                      writeDsec(f, kX, column(std::vector<std::int32_t>{0, 1, 70000, 3, 4, 5}), kT, kP);
                    },
                    false, {"yb.h5: dataset /events/y: row 2: value 70000 outside"}},
        Hdf5Refusal{"p_float32", "pf.h5",
                    [](const std::string& f) { writeDsec(f, kX, kY, kT, column(std::vector<float>{0, 0.9f, 1, 0, 1, 0})); },
                    true, {"pf.h5: dataset /events/p: type float32, expected integers"}},
        Hdf5Refusal{"p_seven", "p7.h5",
                    [](const std::string& f) {
                      writeDsec(f, kX, kY, kT, column(std::vector<std::uint8_t>{0, 1, 7, 0, 1, 0}));
                    },
                    false, {"p7.h5: dataset /events/p: row 2: polarity 7 (expected 0 or 1)"}},
        Hdf5Refusal{"x_strings", "xs.h5",
                    [](const std::string& f) {
                      const Column strings = [](celc::test::h5::File& h, const std::string& name) {
                        h.writeStrings(name, {"1", "2", "3", "4", "5", "6"});
                      };
                      writeDsec(f, strings, kY, kT, kP);
                    },
                    true, {"xs.h5: dataset /events/x: type variable-length string, expected integers"}},
        // MVSEC: N x 4 numbers, polarity -1 / 1 (0 read as OFF); 0.9 is not a polarity.
        Hdf5Refusal{"mvsec_polarity_fraction", "mp.h5",
                    [](const std::string& f) {
                      auto ev = mvsecEvents(5, 1.0, 1e-3);
                      ev[4 * 3 + 3] = 0.9;
                      celc::test::h5::File h(f);
                      h.write("davis/left/events", ev, {5, 4});
                    },
                    false, {"mp.h5: dataset /davis/left/events, event 3: polarity 0.9"}},
        Hdf5Refusal{"mvsec_strings", "ms.h5",
                    [](const std::string& f) {
                      celc::test::h5::File h(f);
                      h.writeFixedStrings("davis/left/events", {"a", "b"}, 1);
                    },
                    true, {"ms.h5: dataset /davis/left/events: type string of 1 bytes"}}),
    [](const ::testing::TestParamInfo<Hdf5Refusal>& i) { return std::string(i.param.label); });
