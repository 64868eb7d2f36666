// The one configuration schema (core/fields.hpp, core/yaml.hpp): shipped files
// regenerate byte for byte, every registered field survives a write and a read,
// the schema covers every member of the options structs, and bad YAML is an
// error naming the file, the line and the key.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "celc/config/config.hpp"
#include "celc/core/yaml.hpp"
#include "celc/io/event_reader.hpp"
#include "celc/pipeline/batch.hpp"
#include "celc/pipeline/run_config.hpp"
#include "celc/pipeline/shipped_configs.hpp"
#include "celc/sim/render_sequence.hpp"

namespace celc {
namespace {

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Changes every field it visits to a value different from the one it holds.
class Perturb final : public FieldVisitor {
 public:
  void field(const FieldInfo&, bool& v) override { v = !v; }
  void field(const FieldInfo&, int& v) override { v += 3; }
  void field(const FieldInfo&, unsigned& v) override { v += 3; }
  void field(const FieldInfo&, long& v) override { v += 3; }
  void field(const FieldInfo&, unsigned long& v) override { v += 3; }
  void field(const FieldInfo&, double& v) override { v = std::isfinite(v) ? v * 1.5 + 0.25 : 7.5; }
  void field(const FieldInfo&, std::string& v) override { v += "x"; }
  void field(const FieldInfo&, Vec2& v) override { v = v.allFinite() ? Vec2(v + Vec2(0.5, -0.25)) : Vec2(1, 2); }
  void field(const FieldInfo&, Vec3& v) override {
    v = v.allFinite() ? Vec3(v + Vec3(0.5, -0.25, 0.125)) : Vec3(1, 2, 3);
  }
  void field(const FieldInfo&, std::vector<double>& v, const std::vector<std::size_t>& sizes) override {
    for (double& x : v) x += 0.5;
    if (!sizes.empty() && std::find(sizes.begin(), sizes.end(), v.size()) == sizes.end()) v.resize(sizes.back(), 1.0);
  }
  void choice(const FieldInfo&, std::string& v, const std::vector<std::string>& allowed) override {
    const auto it = std::find(allowed.begin(), allowed.end(), v);
    v = allowed[(static_cast<std::size_t>(it - allowed.begin()) + 1) % allowed.size()];
  }
  void choices(const FieldInfo&, std::vector<std::string>& v, const std::vector<std::string>& allowed) override {
    if (v.size() > 1) v.erase(v.begin());
    else v.push_back(allowed.front() == (v.empty() ? "" : v[0]) ? allowed.back() : allowed.front());
  }
  void section(const FieldInfo&, const std::function<void(FieldVisitor&)>& body) override { body(*this); }
  void sequence(const FieldInfo&, std::size_t& count,
                const std::function<void(std::size_t, FieldVisitor&)>& item) override {
    ++count;
    for (std::size_t i = 0; i < count; ++i) item(i, *this);
  }
};

// Records which bytes of an object the schema reaches.
class Coverage final : public FieldVisitor {
 public:
  Coverage(const void* base, std::size_t size, std::size_t align)
      : base_(static_cast<const char*>(base)), size_(size), align_(align) {}
  void field(const FieldInfo&, bool& v) override { member(&v, sizeof v); }
  void field(const FieldInfo&, int& v) override { member(&v, sizeof v); }
  void field(const FieldInfo&, unsigned& v) override { member(&v, sizeof v); }
  void field(const FieldInfo&, long& v) override { member(&v, sizeof v); }
  void field(const FieldInfo&, unsigned long& v) override { member(&v, sizeof v); }
  void field(const FieldInfo&, double& v) override { member(&v, sizeof v); }
  void field(const FieldInfo&, std::string& v) override { member(&v, sizeof v); }
  void field(const FieldInfo&, Vec2& v) override { member(&v, sizeof v); }
  void field(const FieldInfo&, Vec3& v) override { member(&v, sizeof v); }
  void field(const FieldInfo&, std::vector<double>&, const std::vector<std::size_t>&) override {}
  void choice(const FieldInfo&, std::string&, const std::vector<std::string>&) override {}
  void choices(const FieldInfo&, std::vector<std::string>&, const std::vector<std::string>&) override {}
  void section(const FieldInfo&, const std::function<void(FieldVisitor&)>& body) override { body(*this); }
  void sequence(const FieldInfo&, std::size_t&, const std::function<void(std::size_t, FieldVisitor&)>&) override {}
  void member(const void* address, std::size_t size) override {
    const char* p = static_cast<const char*>(address);
    if (p >= base_ && p + size <= base_ + size_) ranges_.emplace_back(p - base_, p - base_ + size);
  }
  /// Byte ranges of the object that no field reaches, beyond alignment padding
  /// (< 8 bytes, or < 16 bytes before a 16-byte aligned member such as Vec2,
  /// or the tail padding up to the object's alignment).
  std::vector<std::pair<std::size_t, std::size_t>> gaps() const {
    auto r = ranges_;
    std::sort(r.begin(), r.end());
    std::vector<std::pair<std::size_t, std::size_t>> out;
    std::size_t end = 0;
    for (const auto& [b, e] : r) {
      const bool padding = b - end < 8 || (b % 16 == 0 && b - end < 16);
      if (b > end && !padding) out.emplace_back(end, b);
      end = std::max(end, e);
    }
    if (size_ > end && size_ - end >= std::max<std::size_t>(8, align_)) out.emplace_back(end, size_);
    return out;
  }

 private:
  const char* base_;
  std::size_t size_, align_;
  std::vector<std::pair<std::size_t, std::size_t>> ranges_;
};

template <class Config>
std::map<std::string, std::string> values(Config& c) {
  std::map<std::string, std::string> m;
  for (const FieldEntry& f : listFields([&](FieldVisitor& v) { describe(v, c); })) m[f.key] = f.value;
  return m;
}

// Perturbs every field, writes, reads onto the defaults, compares field by field.
template <class Config>
void expectEveryFieldRoundTrips() {
  Config perturbed;
  Perturb perturb;
  describe(perturb, perturbed);
  const std::string yaml = writeYaml([&](FieldVisitor& v) { describe(v, perturbed); });
  Config back;
  readYaml(yaml, "roundtrip.yaml", [&](FieldVisitor& v) { describe(v, back); });
  Config defaults;
  const auto want = values(perturbed), got = values(back), before = values(defaults);
  ASSERT_GT(want.size(), 20u);
  for (const auto& [key, value] : want) {
    ASSERT_TRUE(got.count(key)) << key;
    EXPECT_EQ(got.at(key), value) << key;
    EXPECT_NE(before.count(key) ? before.at(key) : std::string("<absent>"), value)
        << key << ": the perturbation did not change it";
  }
  EXPECT_EQ(got.size(), want.size());
}

template <class Config>
void expectSchemaCoversEveryMember() {
  Config c;
  Coverage coverage(&c, sizeof c, alignof(Config));
  describe(coverage, c);
  for (const auto& [b, e] : coverage.gaps())
    ADD_FAILURE() << "bytes [" << b << ", " << e << ") of a " << sizeof c
                  << "-byte config are no registered field: a member without a schema entry";
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ConfigSchema, ShippedFilesAreWhatTheSchemaWrites) {
  const auto files = shippedConfigs();
  ASSERT_EQ(files.size(), 3u);
  for (const ShippedConfig& f : files)
    EXPECT_EQ(readText(std::string(CELC_SOURCE_DIR "/config/") + f.file), f.text)
        << "config/" << f.file << " differs from the schema: run `celc config --write-defaults config/`";
}

TEST(ConfigSchema, KeyReferencePagesAreWhatTheSchemaWrites) {
  const auto pages = shippedReferences();
  ASSERT_EQ(pages.size(), 2u);
  for (const ShippedConfig& p : pages)
    EXPECT_EQ(readText(std::string(CELC_SOURCE_DIR "/docs/configuration/") + p.file), p.text)
        << "docs/configuration/" << p.file
        << " differs from the schema: run `celc config --write-reference docs/configuration/`";
}

TEST(ConfigSchema, ShippedFilesReadToTheDefaults) {
  RunConfig run = loadRunConfig(CELC_SOURCE_DIR "/config/run.yaml"), run_default;
  EXPECT_EQ(values(run), values(run_default));
  SimulateConfig sim = loadSimulateConfig(CELC_SOURCE_DIR "/config/simulate.yaml"), sim_default;
  EXPECT_EQ(values(sim), values(sim_default));
}

TEST(ConfigSchema, EveryRunFieldRoundTrips) { expectEveryFieldRoundTrips<RunConfig>(); }
TEST(ConfigSchema, EverySimulateFieldRoundTrips) { expectEveryFieldRoundTrips<SimulateConfig>(); }

TEST(ConfigSchema, CoversEveryMemberOfTheOptions) {
  expectSchemaCoversEveryMember<RunConfig>();
  expectSchemaCoversEveryMember<SimulateConfig>();
  // The check itself: a struct with an unregistered member fails it (members
  // that fit in alignment padding, e.g. a lone bool, can hide from it).
  struct Partial {
    double a = 1.0;
    std::string unregistered = "2";
    int b = 3;
  };
  Partial p;
  Coverage coverage(&p, sizeof p, alignof(Partial));
  coverage.field({"a", "", ""}, p.a);
  coverage.field({"b", "", ""}, p.b);
  EXPECT_EQ(coverage.gaps().size(), 1u);
}

TEST(ConfigSchema, ShippedScenesRoundTrip) {
  for (const char* name : {"sample_davis346_room", "e2e_davis346_room_fast", "davis240_rectangles",
                           "davis346_chessboard"}) {
    SynthConfig c = loadSynthConfig(std::string(CELC_SOURCE_DIR "/config/scenes/") + name + ".yaml");
    const std::string yaml = writeYaml([&](FieldVisitor& v) { describe(v, c); });
    SynthConfig back;
    back.camera = cameraPreset(back.camera_preset);
    readYaml(yaml, name, [&](FieldVisitor& v) { describe(v, back); });
    EXPECT_EQ(writeYaml([&](FieldVisitor& v) { describe(v, back); }), yaml) << name;
  }
}

TEST(ConfigSchema, ErrorsNameFileLineAndKey) {
  RunConfig c;
  auto apply = [&](const std::string& text) { return errorOf([&] { applyRunConfig(text, "b.yaml", c); }); };
  EXPECT_EQ(apply("cluster:\n  smoothnes_deg: 5\n").substr(0, 50), "b.yaml:2: unknown key 'cluster.smoothnes_deg' (all");
  EXPECT_NE(apply("cluster:\n  smoothnes_deg: 5\n").find("smoothness_deg"), std::string::npos);
  EXPECT_EQ(apply("cluster:\n  threads: two\n"), "b.yaml:2: key 'cluster.threads': expected an integer (32 bit), got 'two'");
  EXPECT_EQ(apply("cluster:\n  method: kmeans\n"), "b.yaml:2: key 'cluster.method': expected one of grid, pcl, got 'kmeans'");
  EXPECT_EQ(apply("windows:\n  events: -5\n"), "b.yaml:2: key 'windows.events': expected a non-negative integer, got '-5'");
  EXPECT_EQ(apply("solver:\n  linear:\n    huber_k: .nan\n"), "b.yaml:3: key 'solver.linear.huber_k': expected a number, got '.nan'");
  EXPECT_EQ(apply("solver:\n  linear:\n    max_rows: 1e99\n"), "b.yaml:3: key 'solver.linear.max_rows': expected an integer (32 bit), got '1e99'");
  EXPECT_EQ(apply("motion:\n  fixed_omega: [1, 2]\n"), "b.yaml:2: key 'motion.fixed_omega': expected a list of 3 numbers, found 2");
  EXPECT_EQ(apply("methods: [celc, magic]\n"), "b.yaml:1: key 'methods': expected one of celc, celc_opt, celc_ml, ce3lc, npt, celc_acc, got 'magic'");
  EXPECT_EQ(apply("windows: 3\n"), "b.yaml:1: key 'windows': expected a map of keys, got '3'");
  EXPECT_EQ(apply("windows:\n  events: 1\nwindows:\n  events: 2\n"), "b.yaml:3: key 'windows': given twice (first at line 1)");
  EXPECT_EQ(apply("cluster:\n  seed: 1\n  seed: 2\n"), "b.yaml:3: key 'cluster.seed': given twice (first at line 2)");
  EXPECT_EQ(apply("? [camera]\n: 1\n"), "b.yaml:1: keys must be names, got a list");
  EXPECT_NE(apply("cluster: [1, 2\n").find("b.yaml:"), std::string::npos);
  // Raw bytes of a hostile file never reach the message.
  EXPECT_EQ(apply("a: \"\\\xA4\"\n"), "b.yaml:1: YAML syntax: unknown escape character: <0xA4>");
  EXPECT_EQ(apply("cluster:\n  conf\xB5: 1\n").rfind("b.yaml:2: unknown key 'cluster.conf<0xB5>' (allowed", 0), 0u);
  EXPECT_NE(apply("cluster:\n  smoothness_deg: 200\n").find("smoothness_deg: must be"), std::string::npos);
  EXPECT_NE(apply("cluster:\n  smoothness_noise_factor: -1\n").find("smoothness_noise_factor: must be"),
            std::string::npos);
  EXPECT_NE(apply("cluster:\n  smoothness_min_deg: 0\n").find("smoothness_min_deg: must be"), std::string::npos);
  EXPECT_NE(apply("lines:\n  min_events: 1\n").find("min_events"), std::string::npos);
  // A failed apply leaves the configuration as it was.
  EXPECT_EQ(c.cluster.c_px_per_s, ClusterOptions{}.c_px_per_s);
  EXPECT_NE(apply("cluster:\n  c_px_per_s: 10\n  bogus: 1\n"), "");
  EXPECT_EQ(c.cluster.c_px_per_s, ClusterOptions{}.c_px_per_s);
  applyRunConfig("cluster:\n  c_px_per_s: 250\n  method: pcl\n", "ok.yaml", c);
  EXPECT_EQ(c.cluster.c_px_per_s, 250.0);
  EXPECT_EQ(c.cluster.method, ClusterMethod::Pcl);
}

TEST(ConfigSchema, SetAssignments) {
  RunConfig c;
  applyRunSetting("solver.ml.grid_starts=3", c);
  EXPECT_EQ(c.solver.ml.grid_starts, 3);
  applyRunSetting("solver.npt.min_lines=4", c);
  EXPECT_EQ(c.solver.npt.min_lines, 4);
  applyRunSetting("methods=[npt, celc]", c);
  EXPECT_EQ(c.methods, (std::vector<Method>{Method::Npt, Method::Celc}));
  // A method listed twice would give two identical rows per window: an error.
  EXPECT_NE(errorOf([&] { applyRunSetting("methods=[celc, npt, celc]", c); }).find("methods: celc listed twice"),
            std::string::npos);
  EXPECT_EQ(c.methods, (std::vector<Method>{Method::Npt, Method::Celc}));  // unchanged
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.ml.grid_start=3", c); }),
            "--set solver.ml.grid_start=3: unknown key 'solver.ml.grid_start' (allowed here: second_start, "
            "second_start_max_twist, second_start_deg, grid_starts, max_events, screen_events, profile_lattice, "
            "profile_starts, profile_events, start_iterations, finalists, cheiral_tie, cheiral_min, cheiral_clusters, "
            "huber_scale, cauchy_scale, cauchy_min_tail, tukey_scale, cluster_test, rate_offset)");
  EXPECT_EQ(errorOf([&] { applyRunSetting("windows.events", c); }), "--set windows.events: expected key.path=value");
  EXPECT_EQ(errorOf([&] { applyRunSetting("windows.overlap=2", c); }),
            "--set windows.overlap=2: windows.overlap: must be in [0, 1), got 2");
  EXPECT_EQ(c.windows.overlap, 0.0);
  // celc_opt's Cauchy solve: its two keys, set and refused out of range.
  applyRunSetting("solver.refine.cauchy_scale=0", c);
  EXPECT_EQ(c.solver.refine.cauchy_scale, 0.0);
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.refine.cauchy_scale=-1", c); }),
            "--set solver.refine.cauchy_scale=-1: solver.refine.cauchy_scale: must be >= 0, got -1");
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.refine.cauchy_min_tail=2", c); }),
            "--set solver.refine.cauchy_min_tail=2: solver.refine.cauchy_min_tail: must be in [0, 1], got 2");
  EXPECT_EQ(c.solver.refine.cauchy_min_tail, RefineOptions{}.cauchy_min_tail);  // unchanged
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.refine.tukey_scale=-1", c); }),
            "--set solver.refine.tukey_scale=-1: solver.refine.tukey_scale: must be >= 0, got -1");
  // celc_ml's last refinement: Tukey's biweight at 3 robust scales in `celc run`.
  EXPECT_EQ(RunConfig{}.solver.ml.tukey_scale, 3.0);
  EXPECT_EQ(MlOptions{}.tukey_scale, 3.0);  // the library's default is the tool's
  EXPECT_EQ(SolverOptions::paper().ml.tukey_scale, 0.0);  // the paper's preset: Cauchy
  applyRunSetting("solver.ml.tukey_scale=4.5", c);
  EXPECT_EQ(c.solver.ml.tukey_scale, 4.5);
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.ml.tukey_scale=-1", c); }),
            "--set solver.ml.tukey_scale=-1: solver.ml.tukey_scale: must be >= 0, got -1");
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.ml.tukey_scale=nan", c); }),
            "--set solver.ml.tukey_scale=nan: key 'solver.ml.tukey_scale': expected a number, got 'nan'");
  EXPECT_EQ(c.solver.ml.tukey_scale, 4.5);  // unchanged by a refused value
  // celc_ml's answer in front of the camera: on by default, off in the paper's preset.
  EXPECT_EQ(RunConfig{}.solver.ml.cheiral_min, 0.9);
  EXPECT_EQ(MlOptions{}.cheiral_min, 0.9);
  EXPECT_EQ(SolverOptions::paper().ml.cheiral_min, 0.0);
  EXPECT_EQ(MlOptions{}.cheiral_clusters, 10.0);
  applyRunSetting("solver.ml.cheiral_min=0.8", c);
  EXPECT_EQ(c.solver.ml.cheiral_min, 0.8);
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.ml.cheiral_min=1.5", c); }),
            "--set solver.ml.cheiral_min=1.5: solver.ml.cheiral_min: must be in [0, 1], got 1.5");
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.ml.cheiral_clusters=-1", c); }),
            "--set solver.ml.cheiral_clusters=-1: solver.ml.cheiral_clusters: must be >= 0, got -1");
  EXPECT_EQ(c.solver.ml.cheiral_min, 0.8);
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.refine.starts=0", c); }),
            "--set solver.refine.starts=0: solver.refine.starts: must be in [1, 64], got 0");
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.refine.screen_events=-1", c); }),
            "--set solver.refine.screen_events=-1: solver.refine.screen_events: must be >= 0, got -1");
  applyRunSetting("solver.refine.starts=2", c);
  EXPECT_EQ(c.solver.refine.starts, 2);
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.linear.tukey_k=-2", c); }),
            "--set solver.linear.tukey_k=-2: solver.linear.tukey_k: must be >= 0, got -2");
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.uncertainty.witness_rows=-1", c); }),
            "--set solver.uncertainty.witness_rows=-1: solver.uncertainty.witness_rows: must be >= 0, got -1");
  applyRunSetting("solver.uncertainty.agreement=false", c);
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.uncertainty.witness_rows=1000", c); }),
            "--set solver.uncertainty.witness_rows=1000: solver.uncertainty.witness_rows: > 0 needs agreement: true");
  // The sigma_deg floor of answers behind the camera: on by default, off in the paper's preset.
  EXPECT_EQ(RunConfig{}.solver.uncertainty.cheiral_min, 0.9);
  EXPECT_EQ(UncertaintyOptions{}.cheiral_min, 0.9);
  EXPECT_EQ(SolverOptions::paper().uncertainty.cheiral_min, 0.0);
  EXPECT_EQ(errorOf([&] { applyRunSetting("solver.uncertainty.cheiral_min=-0.1", c); }),
            "--set solver.uncertainty.cheiral_min=-0.1: solver.uncertainty.cheiral_min: must be in [0, 1], got -0.1");
  SimulateConfig s;
  applySimulateSetting("scene.camera.fx=100", s);
  EXPECT_EQ(s.scene.camera.fx, 100.0);
}

// Validation generated from the schema: a field's range (core/fields.hpp)
// refuses the values outside it, naming the key, the range and the value;
// every default and the paper's preset are valid.
TEST(ConfigSchema, RangesOfTheSchemaValidate) {
  EXPECT_EQ(atLeast(0).text(), ">= 0");
  EXPECT_EQ(above(0).text(), "> 0");
  EXPECT_EQ(within(0, 1).text(), "in [0, 1]");
  EXPECT_EQ(withinBelow(0, 1).text(), "in [0, 1)");
  EXPECT_EQ(withinAbove(0, 1e-10).text(), "in (0, 1e-10]");
  EXPECT_EQ(anyFinite().text(), "finite");
  EXPECT_EQ(Range{}.text(), "");
  EXPECT_TRUE(Range{}.contains(NAN));
  EXPECT_FALSE(atLeast(0).contains(INFINITY));
  EXPECT_FALSE(anyFinite().contains(-INFINITY));
  EXPECT_FALSE(above(0).contains(0.0));
  EXPECT_TRUE(withinBelow(0, 1).contains(0.0));
  EXPECT_FALSE(withinBelow(0, 1).contains(1.0));
  LinearOptions linear;
  linear.max_rows = -1;
  linear.huber_k = INFINITY;
  EXPECT_EQ(linear.validate(), "max_rows: must be >= 0, got -1; huber_k: must be finite and > 0, got inf; ");
  SolverOptions solver;
  solver.npt.max_sigma_ratio = 0.0;
  EXPECT_EQ(solver.validate(), "npt.max_sigma_ratio: must be in (0, 1], got 0; ");
  RenderOptions render;
  render.threads = 0;
  render.min_step = 1.0;
  EXPECT_EQ(render.validate(), "threads: must be in [1, 64], got 0; min_step: must be <= max_step; ");
  ImuOptions imu;
  imu.R_cam_imu(0, 0) = 2.0;  // a describe() that refuses a value itself: reported, not thrown
  EXPECT_EQ(imu.validate(), "R_cam_imu: must be a rotation matrix (row-major 3x3); ");
  RunConfig run;
  run.fixed_omega.y() = NAN;
  run.groundtruth.degree = 5;
  run.groundtruth.min_poses = 10;
  EXPECT_EQ(run.validate(),
            "motion.fixed_omega: every element must be finite, got nan; groundtruth.degree: must be in [1, 4], got 5");
  const RunConfig run_defaults;
  EXPECT_EQ(run_defaults.validate(), "");
  const SimulateConfig simulate_defaults;
  EXPECT_EQ(simulate_defaults.validate(), "");
  EXPECT_EQ(SolverOptions::paper().validate(), "");
}

TEST(ConfigSchema, HelpComesFromTheSchema) {
  RunConfig c;
  const std::string help = fieldHelp([&](FieldVisitor& v) { describe(v, c); }, "windows.seconds");
  EXPECT_EQ(help, "window length (policy seconds; 0 otherwise) [s] (YAML windows.seconds, default 0.0)");
}

TEST(ConfigSchema, BatchFile) {
  const auto dir = std::filesystem::temp_directory_path() / "celc_batch_schema_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "b.yaml").string();
  auto write = [&](const std::string& text) { std::ofstream(path, std::ios::binary) << text; };
  std::string seen_base;
  auto base = [&](const std::string& p) {
    seen_base = p;
    RunConfig c;
    c.window_policy = WindowPolicy::Events;
    c.windows.events_per_window = 1234;
    return c;
  };
  write("config: run.yaml\nsequences:\n  - {path: seq, t_end: 0.5}\n"
        "  - path: /abs/other\n    label: b\n    config:\n      windows: {events: 50}\n");
  const BatchSpec spec = readBatch(path, base);
  EXPECT_EQ(seen_base, (dir / "run.yaml").string());
  ASSERT_EQ(spec.entries.size(), 2u);
  EXPECT_EQ(spec.entries[0].label, "seq");
  EXPECT_EQ(spec.entries[0].inputs.events, (dir / "seq").string());
  EXPECT_EQ(spec.entries[0].t_end, 0.5);
  EXPECT_EQ(spec.entries[0].config.windows.events_per_window, 1234u);
  EXPECT_EQ(spec.entries[1].inputs.events, "/abs/other");
  EXPECT_EQ(spec.entries[1].config.windows.events_per_window, 50u);
  write("sequences:\n  - {path: a}\n  - {path: b, config: {windows: {evnts: 5}}}\n");
  EXPECT_EQ(errorOf([&] { readBatch(path, base); }).substr(path.size()),
            ":3: unknown key 'sequences[1].config.windows.evnts' (allowed here: policy, events, seconds, overlap, "
            "t_start, t_end, read_batch, keep_partial, partial_min_share, max_windows_per_second, max_events, parallax_px, "
            "no_parallax_px, min_seconds, max_seconds, slow_turn_max_seconds, slow_turn_rad, step_seconds, "
            "probe_events, max_events_in_flight)");
  write("sequences:\n  - {path: a/x}\n  - {path: b/x}\n");
  EXPECT_EQ(errorOf([&] { readBatch(path, base); }).substr(path.size()),
            ":3: key 'sequences[1].label': duplicate label 'x'");
  write("sequences: []\n");
  EXPECT_EQ(errorOf([&] { readBatch(path, base); }).substr(path.size()), ":1: key 'sequences': expected a non-empty list");
  write("sequences:\n  - {label: a}\n");
  EXPECT_EQ(errorOf([&] { readBatch(path, base); }).substr(path.size()), ":2: key 'sequences[0]': missing key 'sequences[0].path'");
  std::filesystem::remove_all(dir);
}

// ---- the readers' time checks in the schema ---------------------------------------

TEST(IoRobustness, ReaderOptionsSchemaHasTheTimeChecks) {
  ReaderOptions o;
  const auto yaml = writeYaml([&](FieldVisitor& v) { describe(v, o); });
  for (const char* key : {"max_time_jump", "backwards_tolerance", "backwards", "max_outside_share"})
    EXPECT_NE(yaml.find(key), std::string::npos) << key;
}

}  // namespace
}  // namespace celc
