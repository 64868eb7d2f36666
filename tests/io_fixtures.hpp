#pragma once
// The bag / HDF5 fixtures of the io tests: written into the build tree by
// tests/fixtures/make_fixtures.sh (celc synth, then celc_make_fixtures: the
// test tree's bag writer and libhdf5). CTest runs it once as the setup test
// `io_fixtures`; a test binary run directly makes them when missing.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "celc/io/event_reader.hpp"
#include "io_test_util.hpp"

namespace celc::test {

/// The fixture folder (tests/fixtures/make_fixtures.cpp lists its files); "" when they cannot be made.
inline const std::string& ioFixtureDir() {
  static const std::string dir = [] {
    const std::string d = CELC_FIXTURE_DIR;
    if (!std::filesystem::exists(d + "/complete")) {
      const std::string cmd = "sh '" CELC_SOURCE_DIR "/tests/fixtures/make_fixtures.sh' '" CELC_BINARY
                              "' '" CELC_MAKE_FIXTURES "' '" CELC_SOURCE_DIR "' '" + d + "' > '" + d + ".log' 2>&1";
      if (std::system(cmd.c_str()) != 0) return std::string();
    }
    return d;
  }();
  return dir;
}
inline std::string fixture(const std::string& name) { return ioFixtureDir() + "/" + name; }
inline std::string fixtureSequence() { return ioFixtureDir() + "/seq"; }
/// The fixture sequence's events as its text reader gives them (the reference
/// every other format must reproduce).
inline std::vector<Event> fixtureTextEvents() {
  auto r = openEventSource(fixtureSequence());
  return readAllEvents(*r);
}

#define CELC_REQUIRE_IO_FIXTURES() \
  ASSERT_FALSE(::celc::test::ioFixtureDir().empty()) << "tests/fixtures/make_fixtures.sh failed: see " CELC_FIXTURE_DIR ".log"

/// Same events, bit for bit (time, pixel, polarity); the first difference is reported.
inline void expectSameEvents(const std::vector<Event>& a, const std::vector<Event>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].t != b[i].t || a[i].x != b[i].x || a[i].y != b[i].y || a[i].on != b[i].on) {
      ADD_FAILURE() << "event " << i << ": (" << a[i].t << ", " << a[i].x << ", " << a[i].y << ", " << a[i].on
                    << ") vs (" << b[i].t << ", " << b[i].x << ", " << b[i].y << ", " << b[i].on << ")";
      return;
    }
  }
}

}  // namespace celc::test
