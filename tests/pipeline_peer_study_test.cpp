// The peer study module (pipeline/peer_study.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "celc/pipeline/peer_study.hpp"

using namespace celc;

// The cells: the V x sigma grid plus one-factor sweeps around the base,
// without duplicates (25 distinct cells), the base in every sweep.
TEST(PeerStudy, CellsCoverTheGridAndSweeps) {
  const auto cells = peerStudyCells();
  EXPECT_EQ(cells.size(), 25u);
  EXPECT_EQ(cells.front().groups, "base;grid;omega;lines;events;outliers");
  EXPECT_EQ(std::count_if(cells.begin(), cells.end(),
                          [](const PeerCell& c) { return c.groups.find("grid") != std::string::npos; }),
            16);
  for (size_t i = 0; i < cells.size(); ++i)
    for (size_t j = i + 1; j < cells.size(); ++j)
      EXPECT_FALSE(cells[i].speed == cells[j].speed && cells[i].sigma_px == cells[j].sigma_px &&
                   cells[i].omega_error_deg_s == cells[j].omega_error_deg_s &&
                   cells[i].lines == cells[j].lines &&
                   cells[i].events_per_line == cells[j].events_per_line &&
                   cells[i].outliers == cells[j].outliers);
  EXPECT_NEAR(cells.front().parallaxRatio(PeerSceneOptions{}), 0.25, 1e-12);
}

// Same rows with 1 and 2 threads; every method ok on a clean cell; the bound
// is positive with noise and zero without; a method's ratio is its RMS over the bound.
TEST(PeerStudy, DeterministicAcrossThreadsAndConsistent) {
  PeerCell noisy;  // base: V 2, sigma 1
  noisy.speed = 5.0;
  noisy.events_per_line = 60;
  noisy.groups = "t";
  PeerCell clean = noisy;
  clean.sigma_px = 0.0;
  PeerStudyConfig cfg;
  cfg.trials = 6;
  cfg.solver.check_parallax = false;
  const auto a = runPeerStudy({noisy, clean}, cfg, 1);
  const auto b = runPeerStudy({noisy, clean}, cfg, 2);
  ASSERT_EQ(a.size(), 2 * cfg.methods.size());
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].phi_median_agn_deg, b[i].phi_median_agn_deg) << i;
    EXPECT_EQ(a[i].crlb_rms_deg, b[i].crlb_rms_deg) << i;
  }
  for (const auto& r : a) {
    EXPECT_EQ(r.trials, 6);
    if (r.cell.sigma_px > 0) {
      EXPECT_GT(r.crlb_rms_deg, 0.0);
      if (r.n_ok > 0) {
        EXPECT_NEAR(r.ratio, r.rms_agn_deg / r.crlb_rms_deg, 1e-12);
      }
    } else {
      EXPECT_EQ(r.crlb_rms_deg, 0.0);
      EXPECT_TRUE(std::isnan(r.ratio));
    }
    if (r.method == Method::Npt || r.method == Method::CelcMl) {
      EXPECT_EQ(r.n_ok, 6) << toString(r.method);
      if (r.cell.sigma_px == 0.0) {
        EXPECT_LT(r.phi_median_agn_deg, 1e-5) << toString(r.method);
      }
    }
  }
  const std::string header = peerCsvHeader();
  const std::string row = peerCsvRow(a.front(), cfg.scene);
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), std::count(row.begin(), row.end(), ','));
}
