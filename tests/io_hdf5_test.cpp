// HDF5 input, DSEC and MVSEC layouts: the fixtures (tests/fixtures/make_fixtures.py)
// hold the sequence `celc synth` rendered as text, and must read back as it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "celc/io/event_reader.hpp"
#include "celc/io/text_io.hpp"
#include "io_fixtures.hpp"
#include "cli_util.hpp"
#include "io_test_util.hpp"

namespace fs = std::filesystem;
using namespace celc;
using celc::test::fixture;
using celc::test::fixtureSequence;
using celc::test::ioErrorOf;

TEST(IoHdf5, DsecLayoutReadsAsTheText) {
  CELC_REQUIRE_IO_FIXTURES();
  auto r = openEventSource(fixture("seq_dsec.h5"));
  EXPECT_EQ(r->format(), Format::Hdf5);
  celc::test::expectSameEvents(readAllEvents(*r), celc::test::fixtureTextEvents());
  EXPECT_EQ(r->warnings().total(), 0u);
  EXPECT_TRUE(r->readImu().empty());
  EXPECT_TRUE(r->readPoses().empty());
}

TEST(IoHdf5, BloscCompressedDsecReadsAsTheText) {
  CELC_REQUIRE_IO_FIXTURES();
  if (!fs::exists(fixture("seq_blosc.h5"))) GTEST_SKIP() << "no blosc filter (hdf5-filter-plugin-blosc-serial)";
  auto r = openEventSource(fixture("seq_blosc.h5"));
  celc::test::expectSameEvents(readAllEvents(*r), celc::test::fixtureTextEvents());
}

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
  }
}

// A compressed dataset whose filter plugin cannot be found: the error names the filter and the package.
TEST(IoHdf5, MissingFilterPluginIsNamed) {
  CELC_REQUIRE_IO_FIXTURES();
  if (!fs::exists(fixture("seq_blosc.h5"))) GTEST_SKIP() << "no blosc filter (hdf5-filter-plugin-blosc-serial)";
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
