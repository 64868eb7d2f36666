// Writes the seed corpora of the fuzz targets with the project's own writers:
//   celc_fuzz_seeds OUTDIR
// gives OUTDIR/<target>/seed_* for every target of tests/fuzz (small, valid
// inputs plus a few edge cases), so that no shared recording is needed. The
// HDF5 seeds are written here with the HDF5 C library (small, unchunked,
// chunked and deflate-compressed); the ROS bag seeds come from the bag writer
// of the io fixtures (celc_make_fixtures, tests/fixtures/make_fixtures.cpp), which scripts/fuzz.sh
// runs on the small sequence written to OUTDIR/bag_sequence, and a format 1.2
// bag from tests/bag12_writer.hpp.
#include <hdf5.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>

#include "celc/core/yaml.hpp"
#include "celc/io/writers.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/sim/render_sequence.hpp"
#include "bag12_writer.hpp"

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

/// HDF5 seed writing: one dataset of `dims` (rank 0 for a scalar), chunked
/// by `chunk` rows when non-zero, deflate-compressed when `deflate`.
void dataset(hid_t file, const char* name, hid_t type, const std::vector<hsize_t>& dims, const void* data,
             hsize_t chunk = 0, bool deflate = false) {
  const hid_t space = dims.empty() ? H5Screate(H5S_SCALAR) : H5Screate_simple(int(dims.size()), dims.data(), nullptr);
  const hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(lcpl, 1);
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (chunk) {
    std::vector<hsize_t> c = dims;
    c[0] = chunk;
    H5Pset_chunk(dcpl, int(c.size()), c.data());
    if (deflate) H5Pset_deflate(dcpl, 6);
  }
  const hid_t d = H5Dcreate2(file, name, type, space, lcpl, dcpl, H5P_DEFAULT);
  if (d < 0 || H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    std::cerr << "celc_fuzz_seeds: cannot write HDF5 dataset " << name << "\n";
    std::exit(1);
  }
  H5Dclose(d);
  H5Pclose(dcpl);
  H5Pclose(lcpl);
  H5Sclose(space);
}

/// DSEC layout: /events/{x,y,t,p}, /ms_to_idx, /t_offset (times in whole us).
void writeDsec(const fs::path& path, const std::vector<Event>& ev, hsize_t chunk, bool deflate) {
  const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const auto t0 = static_cast<std::int64_t>(std::llround(ev.front().t * 1e6));
  std::vector<std::uint16_t> x, y;
  std::vector<std::uint32_t> t;
  std::vector<std::uint8_t> p;
  std::vector<std::uint64_t> ms;
  for (std::size_t i = 0; i < ev.size(); ++i) {
    x.push_back(std::uint16_t(ev[i].x));
    y.push_back(std::uint16_t(ev[i].y));
    t.push_back(std::uint32_t(std::llround(ev[i].t * 1e6) - t0));
    p.push_back(ev[i].on ? 1 : 0);
    while (std::uint64_t(ms.size()) * 1000 <= t.back()) ms.push_back(i);
  }
  const std::vector<hsize_t> n{ev.size()};
  dataset(f, "/events/x", H5T_NATIVE_UINT16, n, x.data(), chunk, deflate);
  dataset(f, "/events/y", H5T_NATIVE_UINT16, n, y.data(), chunk, deflate);
  dataset(f, "/events/t", H5T_NATIVE_UINT32, n, t.data(), chunk, deflate);
  dataset(f, "/events/p", H5T_NATIVE_UINT8, n, p.data(), chunk, deflate);
  dataset(f, "/ms_to_idx", H5T_NATIVE_UINT64, {ms.size()}, ms.data());
  dataset(f, "/t_offset", H5T_NATIVE_INT64, {}, &t0);
  H5Fclose(f);
}

/// MVSEC layout: /davis/left/{events (N x 4), imu (N x 6), imu_ts, pose (N x 4 x 4), pose_ts}.
void writeMvsec(const fs::path& path, const std::vector<Event>& ev, const std::vector<ImuSample>& imu,
                hsize_t chunk) {
  const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  std::vector<double> rows, im, im_t, pose, pose_t;
  for (const Event& e : ev) rows.insert(rows.end(), {double(e.x), double(e.y), e.t, e.on ? 1.0 : -1.0});
  for (const ImuSample& s : imu) {
    im.insert(im.end(), {s.accel.x(), s.accel.y(), s.accel.z(), s.gyro.x(), s.gyro.y(), s.gyro.z()});
    im_t.push_back(s.t);
  }
  for (int k = 0; k < 3; ++k) {
    pose.insert(pose.end(), {1, 0, 0, 0.1 * k, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1});
    pose_t.push_back(ev.front().t + 0.001 * k);
  }
  dataset(f, "/davis/left/events", H5T_NATIVE_DOUBLE, {ev.size(), 4}, rows.data(), chunk);
  dataset(f, "/davis/left/imu", H5T_NATIVE_DOUBLE, {imu.size(), 6}, im.data());
  dataset(f, "/davis/left/imu_ts", H5T_NATIVE_DOUBLE, {imu.size()}, im_t.data());
  dataset(f, "/davis/left/pose", H5T_NATIVE_DOUBLE, {pose_t.size(), 4, 4}, pose.data());
  dataset(f, "/davis/left/pose_ts", H5T_NATIVE_DOUBLE, {pose_t.size()}, pose_t.data());
  H5Fclose(f);
}

/// DSEC files whose datasets hold other types or values than the layout's
/// (int32 y of -5 and 70000, float64 seconds t, float p, p = 7, a
/// variable-length string x): the reader must name the dataset and row.
void writeDsecOddTypes(const fs::path& dir) {
  const std::uint16_t x[6] = {0, 1, 2, 3, 4, 5};
  const std::int32_t y[6] = {0, 1, 2, -5, 4, 70000};
  const std::int64_t t[6] = {0, 10, 20, 30, 40, 50};
  const double t_s[6] = {0.0, 1e-5, 2e-5, 3e-5, 4e-5, 5e-5};
  const std::uint8_t p[6] = {0, 1, 1, 0, 1, 0}, p7[6] = {0, 1, 7, 0, 1, 0};
  const float p_f[6] = {0.0f, 0.9f, 1.0f, 0.0f, 1.0f, 0.0f};
  const char* x_s[6] = {"0", "1", "2", "3", "4", "5"};
  const std::vector<hsize_t> n{6};
  auto file = [&](const char* name, bool y32, bool t_float, int p_kind, bool x_string) {
    const hid_t f = H5Fcreate((dir / name).c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    const hid_t vstr = H5Tcopy(H5T_C_S1);
    H5Tset_size(vstr, H5T_VARIABLE);
    if (x_string) dataset(f, "/events/x", vstr, n, x_s);
    else dataset(f, "/events/x", H5T_NATIVE_UINT16, n, x);
    if (y32) dataset(f, "/events/y", H5T_NATIVE_INT32, n, y);
    else dataset(f, "/events/y", H5T_NATIVE_UINT16, n, x);
    if (t_float) dataset(f, "/events/t", H5T_NATIVE_DOUBLE, n, t_s);
    else dataset(f, "/events/t", H5T_NATIVE_INT64, n, t);
    if (p_kind == 1) dataset(f, "/events/p", H5T_NATIVE_FLOAT, n, p_f);
    else dataset(f, "/events/p", H5T_NATIVE_UINT8, n, p_kind == 2 ? p7 : p);
    H5Tclose(vstr);
    H5Fclose(f);
  };
  file("seed_dsec_int32_y", true, false, 0, false);
  file("seed_dsec_float_t", false, true, 0, false);
  file("seed_dsec_float_p", false, false, 1, false);
  file("seed_dsec_p7", false, false, 2, false);
  file("seed_dsec_vlen_x", false, false, 0, true);
}

/// `path` with `bytes` written over it at `at`.
void patch(const fs::path& path, std::size_t at, const std::string& bytes) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(std::streamoff(at));
  f.write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: celc_fuzz_seeds OUTDIR\n";
    return 2;
  }
  const fs::path out = argv[1];
  for (const char* t : {"events_text", "rpg_sequence", "calibration", "config_yaml", "aedat2", "aedat31",
                        "aedat4_none", "aedat4_lz4", "aedat4_zstd", "rosbag", "hdf5", "bag_sequence"})
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
  // a corrupt first time; a walk back of 0.9 ms per event
  text(out / "events_text/seed_first_outlier", "10000000 5 5 1\n1.0 1 2 1\n1.001 3 4 0\n1.002 6 7 1\n");
  text(out / "events_text/seed_walking_back", "9.0 1 2 1\n8.9991 1 2 1\n8.9982 1 2 1\n8.9973 1 2 1\n");

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
  {  // the first packet's eventTSOverflow at INT32_MAX (times near 4.6e12 s)
    writeAedat31((out / "aedat31/seed_overflow").string(), ev, {}, "DAVIS240C", 20);
    std::ifstream in(out / "aedat31/seed_overflow", std::ios::binary);
    const std::string b((std::istreambuf_iterator<char>(in)), {});
    patch(out / "aedat31/seed_overflow", b.find("#!END-HEADER\r\n") + 14 + 12, std::string("\xFF\xFF\xFF\x7F", 4));
  }
  {  // the first event's timestamp word 0xFFFFFFFF (bytes 4-7 of the first 8-byte record)
    writeAedat2((out / "aedat2/seed_first_all_ones").string(), ev, {});
    patch(out / "aedat2/seed_first_all_ones", fs::file_size(out / "aedat2/seed_first_all_ones") - 8 * ev.size() + 4,
          std::string(4, '\xFF'));
  }
  writeAedat4((out / "aedat4_none/seed_size_7_digits").string(), ev, {}, 1234567, 180, Aedat4Compression::None, 30,
              true);
  writeAedat4((out / "aedat4_none/seed").string(), ev, im, 240, 180, Aedat4Compression::None, 20, true);
  writeAedat4((out / "aedat4_none/seed_no_table").string(), ev, im, 240, 180, Aedat4Compression::None, 30, false);
  writeAedat4((out / "aedat4_lz4/seed").string(), ev, im, 240, 180, Aedat4Compression::Lz4, 20, true);
  writeAedat4((out / "aedat4_zstd/seed").string(), ev, im, 240, 180, Aedat4Compression::Zstd, 20, true);

  // HDF5: DSEC (contiguous, chunked, deflate) and MVSEC
  writeDsec(out / "hdf5/seed_dsec", ev, 0, false);
  writeDsec(out / "hdf5/seed_dsec_chunked", ev, 16, false);
  writeDsec(out / "hdf5/seed_dsec_deflate", ev, 32, true);
  writeMvsec(out / "hdf5/seed_mvsec", ev, im, 0);
  writeMvsec(out / "hdf5/seed_mvsec_chunked", ev, im, 16);
  writeDsecOddTypes(out / "hdf5");

  // ROS bags: a format 1.2 bag, and the sequence celc_make_fixtures turns into bags (fuzz.sh runs it)
  std::ofstream(out / "rosbag/seed_v12", std::ios::binary) << celc::test::bag12(ev, 20, 240, 180).bytes;
  writeEventsText((out / "bag_sequence/events.txt").string(), ev);
  writeImuText((out / "bag_sequence/imu.txt").string(), im, false);
  writePosesText((out / "bag_sequence/groundtruth.txt").string(), poses);
  text(out / "bag_sequence/calib.yaml",
       "width: 240\nheight: 180\nfx: 200.0\nfy: 200.0\ncx: 120.0\ncy: 90.0\ndistortion: [-0.3, 0.1, 0.0, 0.0, 0.0]\n");
  std::cout << "seeds in " << out.string() << "\n";
  return 0;
}
