// Writes the seed corpora of the fuzz targets with the project's own writers:
//   celc_fuzz_seeds OUTDIR
// gives OUTDIR/<target>/seed_* for every target of tests/fuzz (small, valid
// inputs plus a few edge cases), so that no shared recording is needed.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>

#include "celc/core/yaml.hpp"
#include "celc/io/writers.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/sim/render_sequence.hpp"

namespace fs = std::filesystem;
using namespace celc;

namespace {

std::vector<Event> events(std::size_t n, int w, int h, unsigned seed, double t0) {
  std::mt19937 rng(seed);
  std::vector<Event> ev(n);
  long long t = (long long)(t0 * 1e6);
  for (auto& e : ev) {
    t += static_cast<long long>(rng() % 50);
    e.t = double(t) * 1e-6;
    e.x = float(rng() % unsigned(w));
    e.y = float(rng() % unsigned(h));
    e.on = (rng() & 1) != 0;
  }
  return ev;
}

std::vector<ImuSample> imu(double t0, double t1) {
  std::vector<ImuSample> out;
  for (double t = t0; t < t1; t += 1e-3) {
    ImuSample s;
    s.t = std::round(t * 1e6) * 1e-6;
    s.gyro = Vec3(0.1, -0.2, 0.3);
    s.accel = Vec3(0.0, -9.8, 0.1);
    out.push_back(s);
  }
  return out;
}

void text(const fs::path& p, const std::string& s) {
  std::ofstream(p, std::ios::binary) << s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: celc_fuzz_seeds OUTDIR\n";
    return 2;
  }
  const fs::path out = argv[1];
  for (const char* t : {"events_text", "rpg_sequence", "calibration", "config_yaml", "aedat2", "aedat31",
                        "aedat4_none", "aedat4_lz4", "aedat4_zstd"})
    fs::create_directories(out / t);
  const auto ev = events(60, 240, 180, 1, 1.0);
  const auto im = imu(ev.front().t, ev.back().t);

  // events text: plain, with id column and header, CRLF
  writeEventsText((out / "events_text/seed_plain").string(), ev);
  TextWriteOptions o;
  o.id_column = true;
  o.crlf = true;
  o.header = "id timestamp x y polarity";
  writeEventsText((out / "events_text/seed_header").string(), ev, o);
  text(out / "events_text/seed_outlier", "1.0 1 2 1\n1.001 3 4 0\n10000000 5 5 1\n1.002 6 7 1\n");

  // RPG sequence files
  writeImuText((out / "rpg_sequence/seed_imu_rpg").string(), im, false);
  writeImuText((out / "rpg_sequence/seed_imu_gyro_first").string(), im, true);
  std::vector<PoseSample> poses;
  for (int i = 0; i < 10; ++i) {
    PoseSample p;
    p.t = 1.0 + 0.01 * i;
    p.position = Vec3(0.1 * i, 0, 0);
    p.orientation = Eigen::Quaterniond::Identity();
    poses.push_back(p);
  }
  writePosesText((out / "rpg_sequence/seed_groundtruth").string(), poses);

  // calibration: calib.txt and the YAML schema
  text(out / "calibration/seed_calib_txt", "199.09 198.97 132.19 110.71 -0.368 0.150 -0.0003 -0.0003 0.0\n");
  text(out / "calibration/seed_calib_yaml",
       "camera:\n  width: 240\n  height: 180\n  fx: 200.0\n  fy: 200.0\n  cx: 120.0\n  cy: 90.0\n"
       "  distortion_model: radtan\n  distortion: [-0.3, 0.1, 0.0, 0.0, 0.0]\n"
       "imu:\n  R_cam_imu: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n  time_offset: 0.001\n"
       "body:\n  T_body_cam: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n");

  // run / batch / scene YAML: the schema's writer (first byte: 0 run, 1 batch, 2 scene)
  RunConfig run;
  text(out / "config_yaml/seed_run", std::string(1, '\0') + writeYaml([&](FieldVisitor& v) { describe(v, run); }));
  text(out / "config_yaml/seed_batch",
       std::string(1, '\1') +
           "sequences:\n  - label: a\n    path: ../data/sample_seq\n    config:\n      windows:\n        events: 30000\n"
           "  - label: b\n    path: ../data/sample_seq\n");
  // the scene defaults have no planes: start from a shipped scene, written back by the schema
  SynthConfig scene = loadSynthConfig(std::string(CELC_SOURCE_DIR) + "/config/scenes/davis240_rectangles.yaml");
  text(out / "config_yaml/seed_scene",
       std::string(1, '\2') + writeYaml([&](FieldVisitor& v) { describe(v, scene); }));

  // binary formats
  writeAedat2((out / "aedat2/seed").string(), ev, im);
  writeAedat2((out / "aedat2/seed_davis346").string(), events(40, 346, 260, 2, 4294.967), {}, "DAVIS346B", 500, 4);
  writeAedat31((out / "aedat31/seed").string(), ev, im, "DAVIS240C", 20);
  writeAedat4((out / "aedat4_none/seed").string(), ev, im, 240, 180, Aedat4Compression::None, 20, true);
  writeAedat4((out / "aedat4_none/seed_no_table").string(), ev, im, 240, 180, Aedat4Compression::None, 30, false);
  writeAedat4((out / "aedat4_lz4/seed").string(), ev, im, 240, 180, Aedat4Compression::Lz4, 20, true);
  writeAedat4((out / "aedat4_zstd/seed").string(), ev, im, 240, 180, Aedat4Compression::Zstd, 20, true);
  std::cout << "seeds in " << out.string() << "\n";
  return 0;
}
