// HDF5 input, DSEC and MVSEC layouts: the fixtures (tests/fixtures/make_fixtures.cpp)
// hold the sequence `celc synth` rendered as text, and must read back as it.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <utility>

#include "celc/io/event_reader.hpp"
#include "celc/io/text_io.hpp"
#include "io/aedat_readers.hpp"
#include "io/hdf5_object_header.hpp"
#include "io_fixtures.hpp"
#include "cli_util.hpp"
#include "io_test_util.hpp"

namespace fs = std::filesystem;
using namespace celc;
using celc::test::fixture;
using celc::test::fixtureSequence;
using celc::test::ioErrorOf;

// A DSEC file, uncompressed or blosc-compressed (the parameter), reads as the text.
class IoHdf5Dsec : public ::testing::TestWithParam<const char*> {};

TEST_P(IoHdf5Dsec, DsecLayoutReadsAsTheText) {
  CELC_REQUIRE_IO_FIXTURES();
  const std::string name = std::string(GetParam()) == "blosc" ? "seq_blosc.h5" : "seq_dsec.h5";
  ASSERT_TRUE(fs::exists(fixture(name)))
      << "no blosc filter: scripts/setup.sh installs hdf5-filter-plugin-blosc-serial";
  auto r = openEventSource(fixture(name));
  EXPECT_EQ(r->format(), Format::Hdf5);
  celc::test::expectSameEvents(readAllEvents(*r), celc::test::fixtureTextEvents());
  EXPECT_EQ(r->warnings().total(), 0u);
  EXPECT_TRUE(r->readImu().empty());
  EXPECT_TRUE(r->readPoses().empty());
}
INSTANTIATE_TEST_SUITE_P(Storage, IoHdf5Dsec, ::testing::Values("uncompressed", "blosc"),
                         [](const ::testing::TestParamInfo<const char*>& i) { return std::string(i.param); });

TEST(IoHdf5, MvsecLayoutEventsImuPoses) {
  CELC_REQUIRE_IO_FIXTURES();
  auto r = openEventSource(fixture("seq_mvsec.h5"));
  celc::test::expectSameEvents(readAllEvents(*r), celc::test::fixtureTextEvents());
  const auto imu = r->readImu(), imu_text = readImuText(fixtureSequence() + "/imu.txt");
  ASSERT_EQ(imu.size(), imu_text.size());
  for (std::size_t i = 0; i < imu.size(); ++i) {
    EXPECT_EQ(imu[i].t, imu_text[i].t);
    EXPECT_EQ(imu[i].gyro, imu_text[i].gyro);
    EXPECT_EQ(imu[i].accel, imu_text[i].accel);
  }
  // Poses are stored as 4x4 matrices: the same rotation, to rounding.
  const auto poses = r->readPoses(), poses_text = readPosesText(fixtureSequence() + "/groundtruth.txt");
  ASSERT_EQ(poses.size(), poses_text.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(poses[i].t, poses_text[i].t);
    EXPECT_EQ(poses[i].position, poses_text[i].position);
    EXPECT_NEAR(poses[i].orientation.angularDistance(poses_text[i].orientation), 0.0, 1e-12);
  }
}

// A read in blocks: every batch size gives the same stream; seeking through
// ms_to_idx lands on the first event of the millisecond.
TEST(IoHdf5, BatchesAndSeek) {
  CELC_REQUIRE_IO_FIXTURES();
  const auto text = celc::test::fixtureTextEvents();
  for (std::size_t batch : {1u, 999u, 65536u, 100000u}) {
    auto r = openEventSource(fixture("seq_dsec.h5"));
    std::vector<Event> all, b;
    while (r->next(b, batch)) {
      ASSERT_LE(b.size(), batch);
      all.insert(all.end(), b.begin(), b.end());
    }
    celc::test::expectSameEvents(all, text);
  }
  auto r = openEventSource(fixture("seq_dsec.h5"));
  ASSERT_TRUE(r->seekTime(0.1));
  std::vector<Event> b;
  ASSERT_TRUE(r->next(b, 10));
  EXPECT_GE(b.front().t, 0.1 - 1e-3);
  EXPECT_LT(b.front().t, 0.1 + 1e-9);
  const auto first = std::find_if(text.begin(), text.end(), [](const Event& e) { return e.t >= 0.1; });
  const auto k = std::find_if(text.begin(), text.end(), [&](const Event& e) { return e.t == b.front().t; });
  EXPECT_LE(k - text.begin(), first - text.begin());
}

TEST(IoHdf5, MissingDatasetsAndDamagedFilesGiveOneLineErrors) {
  CELC_REQUIRE_IO_FIXTURES();
  std::string m = ioErrorOf([] { openEventSource(fixture("bad_layout.h5")); });
  EXPECT_NE(m.find("bad_layout.h5: neither the DSEC layout (/events/x"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  m = ioErrorOf([] { openEventSource(fixture("bad_dsec.h5")); });
  EXPECT_NE(m.find("bad_dsec.h5: dataset /events/p is missing"), std::string::npos) << m;
  m = ioErrorOf([] { openEventSource(fixture("bad_mvsec.h5")); });
  EXPECT_NE(m.find("bad_mvsec.h5: dataset /davis/left/events: has 3 columns, expected 4 (x, y, t, p)"),
            std::string::npos)
      << m;
  // Declared with 10^12 rows and never written: refused at once instead of
  // read for hours as fill values.
  m = ioErrorOf([] { openEventSource(fixture("bad_unwritten.h5")); });
  EXPECT_NE(m.find("bad_unwritten.h5: dataset /events/"), std::string::npos) << m;
  EXPECT_NE(m.find("chunks but stores 0: rows that were never written"), std::string::npos) << m;
  m = ioErrorOf([] { openEventSource(fixture("bad_unwritten_mvsec.h5")); });
  EXPECT_NE(m.find("bad_unwritten_mvsec.h5: dataset /davis/left/events: contiguous data of 0 bytes for 32000000000 bytes"),
            std::string::npos)
      << m;
  // An index entry past the events (2^63) and IMU times going back: errors
  // naming the dataset and the entry, not 0 windows or windows `not_covered`.
  m = ioErrorOf([] {
    auto r = openEventSource(fixture("bad_ms_to_idx.h5"));
    r->seekTime(0.2);
  });
  EXPECT_NE(m.find("bad_ms_to_idx.h5: dataset /ms_to_idx: entry "), std::string::npos) << m;
  EXPECT_NE(m.find("is event 9223372036854775808, beyond the"), std::string::npos) << m;
  m = ioErrorOf([] { openEventSource(fixture("bad_imu_ts.h5"))->readImu(); });
  EXPECT_NE(m.find("bad_imu_ts.h5: dataset /davis/left/imu_ts: row 100: time"), std::string::npos) << m;
  EXPECT_NE(m.find("(times must not decrease)"), std::string::npos) << m;
  celc::test::TempDir dir;
  std::ifstream in(fixture("seq_dsec.h5"), std::ios::binary);
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (std::size_t keep : {good.size() / 2, std::size_t(4000), std::size_t(100)}) {
    const std::string path = dir.file("cut.h5");
    std::ofstream(path, std::ios::binary) << good.substr(0, keep);
    m = ioErrorOf([&] {
      auto r = openEventSource(path);
      readAllEvents(*r);
    });
    EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    // cut inside the root group's header (at byte 96 of the fixtures): said before the library reads it
    if (keep == 100) {
      EXPECT_NE(m.find(": object header of /: the file ends inside it (truncated?)"), std::string::npos) << m;
    }
  }
}

// A compressed dataset whose filter plugin cannot be found: the error names the filter and the package.
TEST(IoHdf5, MissingFilterPluginIsNamed) {
  CELC_REQUIRE_IO_FIXTURES();
  ASSERT_TRUE(fs::exists(fixture("seq_blosc.h5")))
      << "no blosc filter: scripts/setup.sh installs hdf5-filter-plugin-blosc-serial";
  const fs::path d = celc::test::freshTempDir("io_hdf5_filter");
  const auto r = celc::test::runCelc("info '" + fixture("seq_blosc.h5") + "'", d);
  ASSERT_EQ(r.status, 0) << r.err;
  // the same with a plugin folder that holds no plugin
  const std::string cmd = "HDF5_PLUGIN_PATH='" + d.string() + "' " CELC_BINARY " info '" + fixture("seq_blosc.h5") +
                          "' > /dev/null 2> '" + (d / "err.txt").string() + "'";
  EXPECT_NE(std::system(cmd.c_str()), 0);
  const std::string err = celc::test::readAll(d / "err.txt");
  EXPECT_NE(err.find("seq_blosc.h5: dataset /events/x: compressed with filter 32001"), std::string::npos) << err;
  EXPECT_NE(err.find("hdf5-filter-plugin-blosc-serial"), std::string::npos) << err;
  EXPECT_EQ(err.find('\n'), err.size() - 1) << err;
  fs::remove_all(d);
}

TEST(IoHdf5, NewestHeaderVersionsReadAsTheText) {
  CELC_REQUIRE_IO_FIXTURES();
  // superblock 3 after a user block, version 2 headers continued in OCHK chunks
  auto r = openEventSource(fixture("seq_dsec_v2.h5"));
  celc::test::expectSameEvents(readAllEvents(*r), celc::test::fixtureTextEvents());
  celc::detail::BinFile raw(fixture("seq_dsec_v2.h5"));
  const celc::detail::Hdf5Superblock sb = celc::detail::readHdf5Superblock(raw);
  EXPECT_EQ(sb.version, 3);
  EXPECT_EQ(sb.base, 512u);
  const auto messages = celc::detail::checkHdf5ObjectHeader(
      raw, sb, celc::detail::hdf5LinkAddress(fixture("seq_dsec_v2.h5"), "/events/x"), "/events/x");
  EXPECT_GE(std::count_if(messages.begin(), messages.end(), [](const auto& m) { return m.type == 0x10; }), 1);
}

namespace {

/// `file` with the message `m` of an object header made a continuation
/// message to `chunk_bytes` bytes at `chunk_address` (8-byte addresses and lengths).
std::string withContinuation(std::string file, const celc::detail::Hdf5Message& m, int header_version,
                             std::uint64_t chunk_address, std::uint64_t chunk_bytes) {
  if (header_version == 1) {
    file[m.data_byte - 8] = 0x10;  // type, u16
    file[m.data_byte - 7] = 0;
  } else {
    file[m.data_byte - 4] = 0x10;  // type, u8 (no creation order)
  }
  for (int i = 0; i < 8; ++i) {
    file[m.data_byte + i] = char((chunk_address >> (8 * i)) & 0xFF);
    file[m.data_byte + 8 + i] = char((chunk_bytes >> (8 * i)) & 0xFF);
  }
  return file;
}

}  // namespace

// The hdf5 fuzz target's finding: a dataset header's message turned into a
// continuation to 4 GB at 1 MB of a small file made libhdf5 reserve 4 GB
// before it compared the chunk with the file's end. Every header the reader
// opens (the root group's, each group's and dataset's) is checked first.
TEST(IoHdf5, HeaderChunksPastTheFileAreRefusedBeforeTheLibraryReadsThem) {
  CELC_REQUIRE_IO_FIXTURES();
  celc::test::TempDir dir;
  for (const char* name : {"seq_dsec.h5", "seq_dsec_v2.h5"}) {
    std::ifstream in(fixture(name), std::ios::binary);
    const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    celc::detail::BinFile raw(fixture(name));
    const celc::detail::Hdf5Superblock sb = celc::detail::readHdf5Superblock(raw);
    const int version = sb.version <= 1 ? 1 : 2;  // the fixtures: the earliest versions, or the newest
    for (const std::string object : {"/", "/events", "/events/y"}) {
      const std::uint64_t address =
          object == "/" ? sb.root_header : celc::detail::hdf5LinkAddress(fixture(name), object);
      const auto messages = celc::detail::checkHdf5ObjectHeader(raw, sb, address, object);
      auto m = std::find_if(messages.begin(), messages.end(), [](const auto& x) { return x.size >= 16; });
      ASSERT_NE(m, messages.end()) << name << " " << object;
      SCOPED_TRACE(std::string(name) + " " + object);
      const std::string path = dir.file("patched.h5");
      std::ofstream(path, std::ios::binary) << withContinuation(good, *m, version, 1u << 20, 0x100080005ull);
      std::string e = ioErrorOf([&] { readAllEvents(*openEventSource(path)); });
      EXPECT_EQ(e, path + ": byte " + std::to_string(m->data_byte) + ": object header of " + object +
                       ": continuation chunk of 4295491589 bytes at address 1048576 passes the file's end (" +
                       std::to_string(good.size()) + " bytes)");
      // a continuation that loops back to its own header is walked once and refused by the library
      std::ofstream(path, std::ios::binary) << withContinuation(good, *m, version, address, 64);
      e = ioErrorOf([&] { readAllEvents(*openEventSource(path)); });
      EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;
      EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
  }
}

namespace {

/// seq_dsec.h5's bytes and the byte of its root group's local heap ("HEAP"),
/// with little-endian u64 access to the bytes (8-byte addresses and lengths).
struct RootHeap {
  std::string file;
  std::uint64_t heap = 0;
  std::uint64_t load(std::uint64_t at) const {
    std::uint64_t x = 0;
    for (int i = 7; i >= 0; --i) x = (x << 8) | std::uint8_t(file[at + i]);
    return x;
  }
  void store(std::uint64_t at, std::uint64_t x) {
    for (int i = 0; i < 8; ++i) file[at + i] = char((x >> (8 * i)) & 0xff);
  }
};

RootHeap rootHeap() {
  RootHeap r;
  std::ifstream in(fixture("seq_dsec.h5"), std::ios::binary);
  r.file.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  celc::detail::BinFile raw(fixture("seq_dsec.h5"));
  const celc::detail::Hdf5Superblock sb = celc::detail::readHdf5Superblock(raw);
  EXPECT_EQ(sb.base, 0u);
  EXPECT_EQ(sb.offset_bytes, 8);
  EXPECT_EQ(sb.length_bytes, 8);
  const auto messages = celc::detail::checkHdf5ObjectHeader(raw, sb, sb.root_header, "/");
  const auto table = std::find_if(messages.begin(), messages.end(), [](const auto& m) { return m.type == 0x11; });
  if (table == messages.end()) {
    ADD_FAILURE() << "no symbol table message in the root group";
    return r;
  }
  r.heap = r.load(table->data_byte + 8);
  return r;
}

/// The reader's error on `file` written to a temporary path, and that path.
std::pair<std::string, std::string> errorOnPatched(const std::string& file, celc::test::TempDir& dir) {
  const std::string path = dir.file("patched.h5");
  std::ofstream(path, std::ios::binary) << file;
  return {ioErrorOf([&] { readAllEvents(*openEventSource(path)); }), path};
}

}  // namespace

// The hdf5 fuzz target's next finding: an old-style group's local heap whose
// data segment claims 88 TB made libhdf5 size a buffer from it while looking
// up a link. The heap of every group the reader walks is checked first.
TEST(IoHdf5, LocalHeapPastTheFileIsRefusedBeforeTheLibraryReadsIt) {
  CELC_REQUIRE_IO_FIXTURES();
  RootHeap r = rootHeap();
  ASSERT_EQ(r.file.substr(r.heap, 4), "HEAP");
  r.store(r.heap + 8, 0x500000000000ull);  // the data segment's size: 88 TB
  celc::test::TempDir dir;
  const auto [e, path] = errorOnPatched(r.file, dir);
  EXPECT_EQ(e.rfind(path + ": byte " + std::to_string(r.heap + 8) +
                        ": object header of /: local heap data of 87960930222080 bytes at address ",
                    0),
            0u)
      << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

// The hdf5 fuzz target's fourth finding: a local heap whose free list loops
// back on itself made libhdf5 allocate a node per step until memory ran out
// (24 GB from a 14 KB file). The free list of every heap the reader walks is
// followed first, at most one block per 16 bytes of its data segment.
TEST(IoHdf5, LocalHeapFreeListThatLoopsIsRefused) {
  CELC_REQUIRE_IO_FIXTURES();
  RootHeap r = rootHeap();
  ASSERT_EQ(r.file.substr(r.heap, 4), "HEAP");
  const std::uint64_t bytes = r.load(r.heap + 8), data = r.load(r.heap + 24);
  ASSERT_GE(bytes, 32u);
  // The list's head at offset 16 of the data segment, a block whose next is itself.
  r.store(r.heap + 16, 16);
  r.store(data + 16, 16);
  r.store(data + 24, 16);
  celc::test::TempDir dir;
  const auto [e, path] = errorOnPatched(r.file, dir);
  EXPECT_EQ(e, path + ": byte " + std::to_string(r.heap + 16) + ": object header of /: local heap free list of more than " +
                   std::to_string(bytes / 16 + 1) + " blocks in " + std::to_string(bytes) + " bytes: it loops");
}

// The hdf5 fuzz target's third finding: a chunked layout of rank 0 made
// libhdf5 divide by zero (SIGFPE) when it opened the dataset. The layout
// message of every dataset is checked before the library opens it.
TEST(IoHdf5, ChunkedLayoutWithoutChunkSizesIsAnErrorNotADivisionByZero) {
  CELC_REQUIRE_IO_FIXTURES();
  celc::test::TempDir dir;
  for (const char* name : {"seq_dsec.h5", "seq_dsec_v2.h5"}) {
    SCOPED_TRACE(name);
    std::ifstream in(fixture(name), std::ios::binary);
    const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    celc::detail::BinFile raw(fixture(name));
    const celc::detail::Hdf5Superblock sb = celc::detail::readHdf5Superblock(raw);
    const auto messages = celc::detail::checkHdf5ObjectHeader(
        raw, sb, celc::detail::hdf5LinkAddress(fixture(name), "/events/t"), "/events/t");
    const auto layout = std::find_if(messages.begin(), messages.end(), [](const auto& m) { return m.type == 0x08; });
    ASSERT_NE(layout, messages.end());
    const std::size_t at = layout->data_byte;
    const int version = good[at];
    ASSERT_EQ(int(good[at + 1]), 2) << "a chunked layout";
    // version 3: rank at 2, sizes (u32) after the 8-byte address; version 4: rank at 3, sizes at 5
    const std::size_t rank_at = at + (version == 3 ? 2 : 3), first_size = at + (version == 3 ? 11 : 5);
    ASSERT_TRUE(version == 3 || version == 4) << version;
    const std::string path = dir.file("layout.h5");
    std::string bad = good;
    bad[rank_at] = 0;
    std::ofstream(path, std::ios::binary) << bad;
    std::string e = ioErrorOf([&] { readAllEvents(*openEventSource(path)); });
    EXPECT_EQ(e, path + ": byte " + std::to_string(at) + ": object header of /events/t: a chunked layout of rank 0 (at least 2)");
    bad = good;
    const int width = version == 3 ? 4 : int(good[at + 4]);
    for (int i = 0; i < width; ++i) bad[first_size + std::size_t(i)] = 0;
    std::ofstream(path, std::ios::binary) << bad;
    e = ioErrorOf([&] { readAllEvents(*openEventSource(path)); });
    EXPECT_EQ(e, path + ": byte " + std::to_string(first_size) +
                     ": object header of /events/t: chunk size 0 in dimension 0");
  }
}

// The hdf5 fuzz target's fifth finding: a chunk index (version 1 B-tree)
// whose leaf pointed at the undefined address made libhdf5 copy from NULL
// (SIGSEGV in H5Dget_num_chunks) on an 11 KB file. Every node of a chunked
// dataset's index is walked first: it must lie in the file, be a chunk node
// ("TREE", type 1) and point inside the file.
TEST(IoHdf5, DamagedChunkIndexIsAnErrorNotACrash) {
  CELC_REQUIRE_IO_FIXTURES();
  std::ifstream in(fixture("seq_dsec.h5"), std::ios::binary);
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  celc::detail::BinFile raw(fixture("seq_dsec.h5"));
  const celc::detail::Hdf5Superblock sb = celc::detail::readHdf5Superblock(raw);
  ASSERT_EQ(sb.offset_bytes, 8);
  const auto messages = celc::detail::checkHdf5ObjectHeader(
      raw, sb, celc::detail::hdf5LinkAddress(fixture("seq_dsec.h5"), "/events/t"), "/events/t");
  const auto layout = std::find_if(messages.begin(), messages.end(), [](const auto& m) { return m.type == 0x08; });
  ASSERT_NE(layout, messages.end());
  const std::size_t at = layout->data_byte;
  ASSERT_EQ(int(good[at]), 3) << "layout version 3: a version 1 B-tree index";
  ASSERT_EQ(int(good[at + 1]), 2) << "a chunked layout";
  const std::size_t rank = std::uint8_t(good[at + 2]);
  RootHeap bytes{good, 0};
  const std::uint64_t node = bytes.load(at + 3);
  ASSERT_EQ(good.substr(node, 4), "TREE");
  ASSERT_EQ(int(good[node + 4]), 1) << "a chunk node";
  ASSERT_GE(bytes.file[node + 6], 1) << "a node with a chunk";
  const std::size_t child0 = node + 8 + 2 * 8 + (8 + 8 * rank);  // after the header and key 0
  const std::string file_end = " beyond the file's end (" + std::to_string(good.size()) + " bytes)";
  celc::test::TempDir dir;
  // A leaf's chunk at the undefined address (the fuzz target's file).
  RootHeap bad = bytes;
  bad.store(child0, ~0ull);
  auto [e, path] = errorOnPatched(bad.file, dir);
  EXPECT_EQ(e, path + ": byte " + std::to_string(child0) + ": object header of /events/t: chunk index: child 0 at address " +
                   std::to_string(~0ull) + "," + file_end);
  // The root node beyond the file's end.
  bad = bytes;
  bad.store(at + 3, good.size() + 64);
  std::tie(e, path) = errorOnPatched(bad.file, dir);
  EXPECT_NE(e.find(": object header of /events/t: chunk index: a node of "), std::string::npos) << e;
  EXPECT_NE(e.find(" at address " + std::to_string(good.size() + 64) + " passes the file's end"), std::string::npos) << e;
  // A node that is not a chunk node.
  bad = bytes;
  bad.file[node + 4] = 0;
  std::tie(e, path) = errorOnPatched(bad.file, dir);
  EXPECT_EQ(e, path + ": byte " + std::to_string(node + 4) +
                   ": object header of /events/t: chunk index: a node of type 0, not a chunk node (1)");
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}
