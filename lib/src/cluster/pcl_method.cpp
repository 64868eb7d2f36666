// The PCL reference method, loaded on its first use. PCL lives in its own
// library, libcelc_cluster_pcl.so, beside libcelc_cluster.so: linked into
// every process it would cost about 35 MB of resident memory and half the
// start-up time (the dynamic loader relocating PCL's template instances) of
// every `celc` command, for a method only comparisons use (docs/decisions.md).
#include <dlfcn.h>

#include <filesystem>
#include <mutex>

#include "cluster/internal.hpp"

namespace celc::detail {
namespace {

using PclGrowFunction = Regions (*)(const Group&, double, const ClusterOptions&, int);

constexpr const char* kPclLibrary = "libcelc_cluster_pcl.so";
constexpr const char* kPclEntry = "celc_cluster_pcl_grower";

struct PclGrower {
  PclGrowFunction grow = nullptr;
  std::string error;  ///< why `grow` is null
};

/// The library next to the one this function is in (its handle stays open for
/// the life of the process).
PclGrower load() {
  PclGrower out;
  Dl_info self{};
  if (dladdr(reinterpret_cast<void*>(&load), &self) == 0 || self.dli_fname == nullptr) {
    out.error = "method pcl: cannot locate libcelc_cluster to find " + std::string(kPclLibrary);
    return out;
  }
  const std::string path = (std::filesystem::path(self.dli_fname).parent_path() / kPclLibrary).string();
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* why = dlerror();
    out.error = "method pcl: " + (why ? std::string(why) : "cannot load " + path);
    return out;
  }
  auto* entry = reinterpret_cast<void* (*)()>(dlsym(handle, kPclEntry));
  if (entry == nullptr) {
    out.error = "method pcl: " + path + " has no " + kPclEntry;
    return out;
  }
  out.grow = reinterpret_cast<PclGrowFunction>(entry());
  return out;
}

const PclGrower& grower() {
  static std::once_flag once;
  static PclGrower loaded;
  std::call_once(once, [] { loaded = load(); });
  return loaded;
}

}  // namespace

std::string pclGrowerError() { return grower().error; }

Regions growPcl(const Group& g, double c, const ClusterOptions& opt, int threads) {
  const PclGrower& pcl = grower();
  if (pcl.grow == nullptr) return Regions{std::vector<int>(g.size(), -1)};  // clusterEvents said why
  return pcl.grow(g, c, opt, threads);
}

}  // namespace celc::detail
