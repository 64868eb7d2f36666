// HDF5 event recordings through the HDF5 C library (Debian libhdf5-dev; a
// compressed dataset needs its filter plugin, e.g. hdf5-filter-plugin-blosc-serial
// for blosc). Two layouts, told apart by their datasets:
//  - DSEC: /events/{x,y} (uint16 [px]), /events/t (integer [us] after
//    /t_offset), /events/p (0/1), /t_offset (int64 [us], 0 when absent),
//    /ms_to_idx (index of the first event of each millisecond; used to seek);
//  - MVSEC: /davis/left/events (N x 4 float64: x [px], y [px], t [s], p in
//    {-1, 1}; 0 is read as OFF), /davis/left/imu (N x 6: accel [m/s^2] then gyro [rad/s], or
//    gyro first with input.imu_columns: gyro_first) with /davis/left/imu_ts
//    [s], /davis/left/pose (N x 4 x 4 T_world_body [m]) with /davis/left/pose_ts [s].
// Events are read in hyperslabs of kBlockEvents: a window never loads the file.
// Every dimension read from the file is checked before it sizes anything, and
// every dataset's type class before its values are read: integers where the
// layout stores them (a float /events/t is an error, not times of 0), values
// range-checked as stored (HDF5's conversion would clamp -5 to 0).
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>

#include "celc/core/text.hpp"
#include "io/aedat_readers.hpp"
#include "io/binary_file.hpp"
#include "io/hdf5_chunk_filters.hpp"
#include "io/hdf5_object_header.hpp"

namespace celc::detail {
namespace {

constexpr hsize_t kBlockEvents = hsize_t(1) << 16;
constexpr hsize_t kMaxSideSamples = hsize_t(1) << 28;  ///< IMU / pose rows read at once

/// An HDF5 identifier closed on scope exit.
class H5Id {
 public:
  H5Id() = default;
  H5Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  H5Id(H5Id&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  H5Id& operator=(H5Id&& o) noexcept {
    std::swap(id_, o.id_);
    std::swap(close_, o.close_);
    return *this;
  }
  H5Id(const H5Id&) = delete;
  H5Id& operator=(const H5Id&) = delete;
  ~H5Id() {
    if (id_ >= 0 && close_) close_(id_);
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

/// A dataset opened with its shape; a filtered (compressed) chunked dataset
/// also with its filters, its chunk's shape and which of its chunks have had
/// their decoded size checked (Hdf5Reader::checkChunks).
struct Dataset {
  std::string name;
  H5Id id, space;
  std::vector<hsize_t> dims;
  std::vector<int> filters;             ///< filter ids in pipeline order; empty when unfiltered
  std::vector<hsize_t> chunk;           ///< chunk shape [elements per dimension] when filtered
  std::uint64_t chunk_bytes = 0;        ///< a chunk's decoded size [bytes] when filtered
  mutable std::vector<bool> checked;    ///< per chunk, row-major over the chunk grid
};

enum class Layout { Dsec, Mvsec };

/// The element type of a dataset as its class, size and sign ("uint16",
/// "float64", "variable-length string", "compound of 12 bytes", ...).
std::string typeName(hid_t type) {
  const std::size_t bytes = H5Tget_size(type);
  const std::string bits = std::to_string(8 * bytes);
  switch (H5Tget_class(type)) {
    case H5T_INTEGER: return (H5Tget_sign(type) == H5T_SGN_NONE ? "uint" : "int") + bits;
    case H5T_FLOAT: return "float" + bits;
    case H5T_STRING:
      return H5Tis_variable_str(type) > 0 ? std::string("variable-length string")
                                          : "string of " + std::to_string(bytes) + " bytes";
    case H5T_ENUM: return "enum of " + std::to_string(bytes) + " bytes";
    case H5T_COMPOUND: return "compound of " + std::to_string(bytes) + " bytes";
    case H5T_VLEN: return "variable-length sequence";
    case H5T_ARRAY: return "array of " + std::to_string(bytes) + " bytes";
    case H5T_BITFIELD: return "bitfield" + bits;
    case H5T_OPAQUE: return "opaque of " + std::to_string(bytes) + " bytes";
    case H5T_REFERENCE: return "reference";
    default: return "unknown type class";
  }
}

/// What a dataset's values must be, checked before they are read (the
/// library's conversion would otherwise clamp, truncate or zero them).
enum class Values { Integer, Number };

class Hdf5Reader final : public EventReader {
 public:
  Hdf5Reader(const std::string& path, const ReaderOptions& o) {
    path_ = path;
    options_ = o;
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // failures come back as return codes, reported here
    // The library reads the root group's header (and the superblock
    // extension's) when it opens the file: they are checked first.
    raw_ = std::make_unique<BinFile>(path);
    superblock_ = readHdf5Superblock(*raw_);
    if (superblock_.extension != ~0ull) {  // first: it may set the chunk B-trees' K
      checked_.insert(superblock_.extension);
      readHdf5ChunkBtreeK(*raw_, superblock_,
                          checkHdf5ObjectHeader(*raw_, superblock_, superblock_.extension, "the superblock extension"));
    }
    checkHeader(superblock_.root_header, "/");
    file_ = H5Id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    if (!file_.valid()) throw IoError(path + ": byte 0: not a readable HDF5 file (damaged or truncated?)");
    file_bytes_ = raw_->size();
    if (exists("/events/x") || exists("/events/t")) {
      layout_ = Layout::Dsec;
      for (const char* n : {"x", "y", "t", "p"}) {
        dsec_[n[0] == 'x' ? 0 : n[0] == 'y' ? 1 : n[0] == 't' ? 2 : 3] =
            open(std::string("/events/") + n, 1, Values::Integer);
      }
      count_ = dsec_[0].dims[0];
      for (const Dataset& d : dsec_)
        if (d.dims[0] != count_)
          fail(d.name, "holds " + std::to_string(d.dims[0]) + " values, /events/x " + std::to_string(count_));
      if (exists("/t_offset")) {
        Dataset off = open("/t_offset", 0, Values::Integer);
        if (H5Dread(off.id.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, &t_offset_us_) < 0)
          fail(off.name, "cannot read the scalar offset");
      }
      notes_.push_back("HDF5 layout DSEC: /events/{x,y,t,p}" + std::string(exists("/ms_to_idx") ? ", /ms_to_idx" : "") +
                       ", t_offset " + std::to_string(t_offset_us_) + " us");
    } else if (exists("/davis/left/events")) {
      layout_ = Layout::Mvsec;
      mvsec_ = open("/davis/left/events", 2, Values::Number);
      if (mvsec_.dims[1] != 4)
        fail(mvsec_.name, "has " + std::to_string(mvsec_.dims[1]) + " columns, expected 4 (x, y, t, p)");
      count_ = mvsec_.dims[0];
      notes_.push_back(std::string("HDF5 layout MVSEC: /davis/left/events") +
                       (exists("/davis/left/imu") ? ", /davis/left/imu" : "") +
                       (exists("/davis/left/pose") ? ", /davis/left/pose" : ""));
    } else {
      throw IoError(path + ": neither the DSEC layout (/events/x, /events/y, /events/t, /events/p) nor the MVSEC "
                           "layout (/davis/left/events) is in the file");
    }
    notes_.push_back(std::to_string(count_) + " events in the file");
    // The block buffers: a small file needs no block of kBlockEvents (2 MB for MVSEC).
    const std::size_t block = std::size_t(std::min<hsize_t>(kBlockEvents, count_));
    if (layout_ == Layout::Dsec) {
      x_.resize(block);
      y_.resize(block);
      t_.resize(block);
      p_.resize(block);
    } else {
      rows_.resize(block * 4);
    }
    width_ = o.width;
    height_ = o.height;
  }
  Format format() const override { return Format::Hdf5; }

  bool next(std::vector<Event>& batch, std::size_t max) override {
    max = startBatch(batch, max);
    while (batch.size() < max) {
      if (cur_ == have_) {
        if (!refill()) break;
        continue;
      }
      drain(batch, max);
    }
    if (batch.size() < max) release(batch, max);
    return !batch.empty();
  }

  std::vector<ImuSample> readImu() override {
    std::vector<ImuSample> imu;
    if (layout_ != Layout::Mvsec || !exists("/davis/left/imu")) return imu;
    Dataset values = open("/davis/left/imu", 2, Values::Number), stamps = open("/davis/left/imu_ts", 1, Values::Number);
    if (values.dims[1] != 6) fail(values.name, "has " + std::to_string(values.dims[1]) + " columns, expected 6");
    if (values.dims[0] != stamps.dims[0])
      fail(stamps.name, "holds " + std::to_string(stamps.dims[0]) + " times for " + std::to_string(values.dims[0]) +
                            " IMU rows");
    const std::vector<double> v = readAll(values, 6), t = readAll(stamps, 1);
    checkTimesDoNotDecrease(stamps, t);
    const bool gyro_first = options_.imu_columns == ImuColumns::GyroFirst;
    imu.resize(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double* r = &v[6 * i];
      imu[i].t = t[i];
      imu[i].accel = gyro_first ? Vec3(r[3], r[4], r[5]) : Vec3(r[0], r[1], r[2]);
      imu[i].gyro = gyro_first ? Vec3(r[0], r[1], r[2]) : Vec3(r[3], r[4], r[5]);
      if (!std::isfinite(t[i]) || !imu[i].accel.allFinite() || !imu[i].gyro.allFinite())
        fail(values.name, "row " + std::to_string(i) + ": a non-finite value");
    }
    return imu;
  }

  std::vector<PoseSample> readPoses() override {
    std::vector<PoseSample> poses;
    if (layout_ != Layout::Mvsec || !exists("/davis/left/pose")) return poses;
    Dataset values = open("/davis/left/pose", 3, Values::Number),
            stamps = open("/davis/left/pose_ts", 1, Values::Number);
    if (values.dims[1] != 4 || values.dims[2] != 4) fail(values.name, "is not N x 4 x 4");
    if (values.dims[0] != stamps.dims[0])
      fail(stamps.name, "holds " + std::to_string(stamps.dims[0]) + " times for " + std::to_string(values.dims[0]) +
                            " poses");
    const std::vector<double> v = readAll(values, 16), t = readAll(stamps, 1);
    checkTimesDoNotDecrease(stamps, t);
    poses.resize(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) {
      Eigen::Matrix4d T;
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) T(r, c) = v[16 * i + 4 * r + c];
      const Mat3 R = T.topLeftCorner<3, 3>();
      if (!T.allFinite() || !std::isfinite(t[i]) || (R.transpose() * R - Mat3::Identity()).norm() > 1e-3)
        fail(values.name, "pose " + std::to_string(i) + ": not a finite rigid transform");
      poses[i].t = t[i];
      poses[i].position = T.topRightCorner<3, 1>();
      poses[i].orientation = Eigen::Quaterniond(R).normalized();
    }
    return poses;
  }

  bool seekTime(double t_start) override {
    if (layout_ != Layout::Dsec || !exists("/ms_to_idx") || !std::isfinite(t_start)) return false;
    Dataset ms = open("/ms_to_idx", 1, Values::Integer);
    const double rel_ms = std::floor((t_start * 1e6 - double(t_offset_us_)) / 1000.0);
    if (rel_ms <= 0) return true;
    const hsize_t k = hsize_t(std::min(rel_ms, double(ms.dims[0] ? ms.dims[0] - 1 : 0)));
    if (ms.dims[0] == 0) return false;
    std::uint64_t idx = 0;
    H5Id mem(H5Screate_simple(1, std::vector<hsize_t>{1}.data(), nullptr), H5Sclose);
    hsize_t start = k, one = 1;
    checkChunks(ms, k, 1);
    H5Sselect_hyperslab(ms.space.get(), H5S_SELECT_SET, &start, nullptr, &one, nullptr);
    if (H5Dread(ms.id.get(), H5T_NATIVE_UINT64, mem.get(), ms.space.get(), H5P_DEFAULT, &idx) < 0)
      fail(ms.name, "cannot read entry " + std::to_string(k));
    // An index past the events would start after the data: 0 windows, silently.
    if (idx > count_)
      fail(ms.name, "entry " + std::to_string(k) + " is event " + std::to_string(idx) + ", beyond the " +
                        std::to_string(count_) + " events (damaged index)");
    next_ = idx;
    cur_ = have_ = 0;
    return true;
  }

 private:
  [[noreturn]] void fail(const std::string& dataset, const std::string& what) const {
    throw IoError(path_ + ": dataset " + dataset + ": " + what);
  }

  /// A time dataset of IMU samples or poses must not go back (the gyro
  /// windows and the ground truth would silently find no samples).
  void checkTimesDoNotDecrease(const Dataset& stamps, const std::vector<double>& t) const {
    for (std::size_t i = 1; i < t.size(); ++i)
      if (t[i] < t[i - 1])
        fail(stamps.name, "row " + std::to_string(i) + ": time " + std::to_string(t[i]) + " s is before row " +
                              std::to_string(i - 1) + "'s " + std::to_string(t[i - 1]) + " s (times must not decrease)");
  }

  /// Checks the object header at `address` once (hdf5_object_header.hpp).
  void checkHeader(std::uint64_t address, const std::string& object) const {
    if (checked_.insert(address).second) checkHdf5ObjectHeader(*raw_, superblock_, address, object);
  }

  /// Checks the header of the object `name` links to, before the library reads
  /// it; only hard links are followed (a soft or external link would make the
  /// library read an object, or a file, these checks never saw).
  void checkLinkTarget(const std::string& name) const {
    H5L_info_t info;
    if (H5Lget_info(file_.get(), name.c_str(), &info, H5P_DEFAULT) < 0)
      throw IoError(path_ + ": " + name + ": its link cannot be read (damaged file)");
    if (info.type != H5L_TYPE_HARD)
      throw IoError(path_ + ": " + name + " is a soft or external link; only hard links are followed");
    checkHeader(std::uint64_t(info.u.address), name);
  }

  bool exists(const std::string& name) const {
    // Each link along the path must exist, and its group's header be checked,
    // before the next is asked about (asking reads the group's header).
    std::size_t p = 0;
    while ((p = name.find('/', p + 1)) != std::string::npos) {
      const std::string group = name.substr(0, p);
      if (H5Lexists(file_.get(), group.c_str(), H5P_DEFAULT) <= 0) return false;
      checkLinkTarget(group);
    }
    return H5Lexists(file_.get(), name.c_str(), H5P_DEFAULT) > 0;
  }

  /// Opens dataset `name` of rank `rank` whose element type holds `values`:
  /// integers (of any size and sign: read as int64, then range-checked) or
  /// numbers (integers or floats, read as double). Any other type (a float
  /// where integers are stored, a string, a compound) is an error naming it.
  Dataset open(const std::string& name, int rank, Values values) const {
    Dataset d;
    d.name = name;
    if (!exists(name)) throw IoError(path_ + ": dataset " + name + " is missing");
    checkLinkTarget(name);
    d.id = H5Id(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
    if (!d.id.valid()) fail(name, "cannot be opened (not a dataset?)");
    {
      H5Id type(H5Dget_type(d.id.get()), H5Tclose);
      if (!type.valid()) fail(name, "its type cannot be read (damaged file)");
      const H5T_class_t c = H5Tget_class(type.get());
      const bool ok = c == H5T_INTEGER || (values == Values::Number && c == H5T_FLOAT);
      if (!ok || H5Tget_size(type.get()) > 8)
        fail(name, "type " + typeName(type.get()) + ", expected " +
                       (values == Values::Integer ? "integers" : "numbers (integers or floats)") +
                       (name == "/events/t" ? " (the DSEC layout stores microseconds as integers)" : ""));
    }
    d.space = H5Id(H5Dget_space(d.id.get()), H5Sclose);
    const int r = H5Sget_simple_extent_ndims(d.space.get());
    if (r != rank) fail(name, "has rank " + std::to_string(r) + ", expected " + std::to_string(rank));
    d.dims.assign(std::size_t(std::max(rank, 0)), 0);
    if (rank > 0) H5Sget_simple_extent_dims(d.space.get(), d.dims.data(), nullptr);
    // A filtered (compressed) dataset whose filter is not available cannot be read: say which.
    H5Id plist(H5Dget_create_plist(d.id.get()), H5Pclose);
    // A chunk is decompressed whole: its size is bounded like an AEDAT packet.
    const int nf = plist.valid() ? H5Pget_nfilters(plist.get()) : 0;
    // Compact (in the header) and contiguous data are stored whole: a stored
    // size other than the dataset's makes the HDF5 library copy from a buffer
    // too small or absent (found by the hdf5 fuzz target). Contiguous data
    // never written (size 0) would read as fill values: refused as well.
    const H5D_layout_t layout = plist.valid() ? H5Pget_layout(plist.get()) : H5D_LAYOUT_ERROR;
    if (layout == H5D_COMPACT || layout == H5D_CONTIGUOUS) {
      H5Id type(H5Dget_type(d.id.get()), H5Tclose);
      double need = type.valid() ? double(H5Tget_size(type.get())) : 0.0;
      for (hsize_t n : d.dims) need *= double(n);
      const double stored = double(H5Dget_storage_size(d.id.get()));
      if (stored != need)
        fail(name, std::string(layout == H5D_COMPACT ? "compact" : "contiguous") + " data of " +
                       byteCountText(stored) + " bytes for " + byteCountText(need) +
                       " bytes of values (damaged file)");
    }
    if (plist.valid() && rank > 0 && layout == H5D_CHUNKED) {
      std::vector<hsize_t> chunk(std::size_t(rank), 0);
      H5Id type(H5Dget_type(d.id.get()), H5Tclose);
      double bytes = type.valid() ? double(H5Tget_size(type.get())) : 8.0;
      if (H5Pget_chunk(plist.get(), rank, chunk.data()) == rank)
        for (hsize_t c : chunk) bytes *= double(c);
      if (nf > 0) {
        d.chunk = chunk;
        d.chunk_bytes = std::uint64_t(bytes);
      }
      if (bytes > double(options_.max_packet_bytes))
        fail(name, "chunks of " + byteCountText(bytes) +
                       " bytes, more than input.max_packet_bytes = " + std::to_string(options_.max_packet_bytes));
      // An unfiltered chunk is stored whole: a stored size that differs from
      // the chunk's (a damaged layout or chunk index) makes the HDF5 library
      // copy beyond its own buffer. A compressed chunk is read into a buffer
      // of its stored size: one larger than the file made it allocate 1.9 GB
      // from 14 KB. (Both found by the hdf5 fuzz target.)
      hsize_t n = 0;
      if (H5Dget_num_chunks(d.id.get(), d.space.get(), &n) < 0)
        fail(name, "its chunk index cannot be read (damaged file)");
      // Rows in chunks that were never written read as fill values: a
      // dataset declared with 10^12 rows and no data would be read for hours
      // as zeros. Every chunk its rows need must be stored.
      double needed = 1.0;
      for (int k = 0; k < rank; ++k)
        if (chunk[std::size_t(k)] > 0)
          needed *= std::ceil(double(d.dims[std::size_t(k)]) / double(chunk[std::size_t(k)]));
      if (double(n) < needed)
        fail(name, "declares " + byteCountText(double(d.dims[0])) + " rows in " + byteCountText(needed) +
                       " chunks but stores " + std::to_string(n) + ": rows that were never written (damaged or "
                       "truncated file)");
      std::vector<hsize_t> offset(std::size_t(rank), 0);
      for (hsize_t i = 0; i < n; ++i) {
        unsigned mask = 0;
        haddr_t addr = 0;
        hsize_t stored = 0;
        if (H5Dget_chunk_info(d.id.get(), d.space.get(), i, offset.data(), &mask, &addr, &stored) < 0)
          fail(name, "chunk " + std::to_string(i) + ": its index cannot be read (damaged file)");
        if (nf == 0 && double(stored) != bytes)
          fail(name, "chunk " + std::to_string(i) + " at byte " + std::to_string(addr) + " holds " +
                         std::to_string(stored) + " bytes, an unfiltered chunk of its layout " +
                         byteCountText(bytes) + " (damaged file)");
        if (nf > 0 && stored > file_bytes_)
          fail(name, "compressed chunk " + std::to_string(i) + " at byte " + std::to_string(addr) + " claims " +
                         std::to_string(stored) + " bytes, more than the file's " + std::to_string(file_bytes_) +
                         " (damaged file)");
        // deflate and blosc add at most a few bytes per kilobyte to data they cannot compress
        if (nf > 0 && double(stored) > 2.0 * bytes + 4096.0)
          fail(name, "compressed chunk " + std::to_string(i) + " at byte " + std::to_string(addr) + " claims " +
                         std::to_string(stored) + " bytes for " + byteCountText(bytes) + " of values (damaged file)");
      }
    }
    if (nf > 0 && (rank == 0 || d.chunk.size() != d.dims.size()))
      fail(name, "filters on a dataset that is not chunked (damaged file)");
    for (int i = 0; i < nf; ++i) {
      unsigned flags = 0, cd[8];
      std::size_t ncd = 8;
      char fname[64] = {0};
      const H5Z_filter_t f = H5Pget_filter2(plist.get(), unsigned(i), &flags, &ncd, cd, sizeof fname, fname, nullptr);
      if (f >= 0 && H5Zfilter_avail(f) <= 0)
        fail(name, "compressed with filter " + std::to_string(int(f)) + " (" + printable(fname, 40) +
                       ") that this HDF5 library cannot load (blosc: install hdf5-filter-plugin-blosc-serial)");
      // The library copies a decoded chunk's full size whatever the filter
      // made of it: only filters whose decoded size the reader can find first
      // are read (hdf5_chunk_filters.hpp).
      if (!hdf5FilterSizeKnown(int(f)))
        fail(name, "compressed with filter " + std::to_string(int(f)) + " (" + printable(fname, 40) +
                       "), whose decoded chunk size this reader cannot check before the HDF5 library copies it "
                       "(readable filters: deflate, shuffle, fletcher32, blosc; e.g. h5repack -f GZIP=4)");
      d.filters.push_back(int(f));
    }
    return d;
  }

  /// Decodes the size of every chunk of the filtered dataset `d` that holds
  /// rows [first, first + rows) and has not been checked yet, before the
  /// library reads it: one that decodes to another size than its layout's is
  /// an error naming its first row (hdf5_chunk_filters.hpp says why).
  void checkChunks(const Dataset& d, hsize_t first, hsize_t rows) const {
    if (d.filters.empty() || rows == 0) return;
    const std::size_t rank = d.dims.size();
    std::vector<hsize_t> grid(rank);  // chunks per dimension
    std::size_t total = 1;
    for (std::size_t k = 0; k < rank; ++k) {
      grid[k] = (d.dims[k] + d.chunk[k] - 1) / d.chunk[k];
      total *= std::size_t(grid[k]);
    }
    if (d.checked.size() != total) d.checked.assign(total, false);
    std::vector<hsize_t> at(rank, 0), offset(rank, 0);  // a chunk's grid index and its first element
    for (at[0] = first / d.chunk[0]; at[0] <= (first + rows - 1) / d.chunk[0]; ++at[0]) {
      std::fill(at.begin() + 1, at.end(), 0);
      for (;;) {  // every chunk of this row of chunks
        std::size_t linear = 0;
        for (std::size_t k = 0; k < rank; ++k) linear = linear * std::size_t(grid[k]) + std::size_t(at[k]);
        if (!d.checked[linear]) {
          checkChunk(d, at, offset);
          d.checked[linear] = true;
        }
        std::size_t k = rank;
        while (--k > 0 && ++at[k] == grid[k]) at[k] = 0;
        if (k == 0) break;
      }
    }
  }

  /// checkChunks for the chunk at grid index `at` (`offset`: scratch).
  void checkChunk(const Dataset& d, const std::vector<hsize_t>& at, std::vector<hsize_t>& offset) const {
    for (std::size_t k = 0; k < at.size(); ++k) offset[k] = at[k] * d.chunk[k];
    const std::string where = "the chunk at row " + std::to_string(offset[0]);
    hsize_t stored = 0;
    if (H5Dget_chunk_storage_size(d.id.get(), offset.data(), &stored) < 0)
      fail(d.name, where + ": its stored size cannot be read (damaged file)");
    chunk_stored_.resize(std::size_t(stored));
    std::uint32_t skipped = 0;
    if (H5Dread_chunk(d.id.get(), H5P_DEFAULT, offset.data(), &skipped, chunk_stored_.data()) < 0)
      fail(d.name, where + ": cannot be read (damaged file)");
    std::uint64_t decoded = 0;
    try {
      decoded = decodedChunkBytes(d.filters, skipped, chunk_stored_, d.chunk_bytes, chunk_decoded_);
    } catch (const std::runtime_error& e) {
      fail(d.name, where + ": " + e.what() + " (damaged file)");
    }
    if (decoded != d.chunk_bytes)
      fail(d.name, where + " decodes to " + (decoded > d.chunk_bytes ? "more than " + std::to_string(d.chunk_bytes)
                                                                       : std::to_string(decoded)) +
                       " bytes, its layout's " + std::to_string(d.chunk_bytes) + " (damaged file)");
  }

  /// Every value of a small dataset (IMU, poses) as double, `cols` per row.
  std::vector<double> readAll(const Dataset& d, std::size_t cols) const {
    if (d.dims[0] > kMaxSideSamples) fail(d.name, "holds more than " + std::to_string(kMaxSideSamples) + " rows");
    checkChunks(d, 0, d.dims[0]);
    std::vector<double> v(std::size_t(d.dims[0]) * cols);
    if (!v.empty() && H5Dread(d.id.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0)
      fail(d.name, "cannot be read as numbers");
    return v;
  }

  /// Reads rows [next_, next_ + n) of `d` (rank 1 or rows x cols) into `dst`.
  void readBlock(const Dataset& d, hid_t type, void* dst, hsize_t n) {
    hsize_t start[2] = {next_, 0}, count[2] = {n, d.dims.size() > 1 ? d.dims[1] : 1};
    const int rank = int(d.dims.size());
    checkChunks(d, next_, n);
    H5Id mem(H5Screate_simple(rank, count, nullptr), H5Sclose);
    if (H5Sselect_hyperslab(d.space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr) < 0 ||
        H5Dread(d.id.get(), type, mem.get(), d.space.get(), H5P_DEFAULT, dst) < 0)
      fail(d.name, "event " + std::to_string(next_) + ": cannot read " + std::to_string(n) +
                       " values (damaged file, or a compressed chunk whose filter is missing)");
  }

  bool refill() {
    if (next_ >= count_) return false;
    const hsize_t n = std::min(kBlockEvents, count_ - next_);
    if (layout_ == Layout::Dsec) {
      // Every integer type converts to int64 exactly (uint64 beyond it is
      // clamped, and out of range below): the values are checked as stored.
      readBlock(dsec_[0], H5T_NATIVE_INT64, x_.data(), n);
      readBlock(dsec_[1], H5T_NATIVE_INT64, y_.data(), n);
      readBlock(dsec_[2], H5T_NATIVE_INT64, t_.data(), n);
      readBlock(dsec_[3], H5T_NATIVE_INT64, p_.data(), n);
    } else {
      readBlock(mvsec_, H5T_NATIVE_DOUBLE, rows_.data(), n);
    }
    block_start_ = next_;
    next_ += n;
    have_ = std::size_t(n);
    cur_ = 0;
    return true;
  }

  void drain(std::vector<Event>& batch, std::size_t max) {
    for (; cur_ < have_ && batch.size() < max; ++cur_) {
      auto where = [&] {
        return path_ + ": dataset " + (layout_ == Layout::Dsec ? "/events" : "/davis/left/events") + ", event " +
               std::to_string(block_start_ + cur_);
      };
      Event e;
      double x, y;
      if (layout_ == Layout::Dsec) {
        const std::string row = std::to_string(block_start_ + cur_);
        for (int k = 0; k < 2; ++k) {
          const std::int64_t v = (k == 0 ? x_ : y_)[cur_];
          if (v < 0 || v > 65535)
            fail(dsec_[k].name, "row " + row + ": value " + std::to_string(v) + " outside [0, 65535] (pixels)");
        }
        if (p_[cur_] != 0 && p_[cur_] != 1)
          fail(dsec_[3].name, "row " + row + ": polarity " + std::to_string(p_[cur_]) + " (expected 0 or 1)");
        x = double(x_[cur_]);
        y = double(y_[cur_]);
        std::int64_t us = 0;
        if (__builtin_add_overflow(t_offset_us_, t_[cur_], &us))
          fail(dsec_[2].name, "row " + row + ": timestamp " + std::to_string(t_[cur_]) + " us plus t_offset overflows");
        if (us >= kMaxExactMicroseconds || us <= -kMaxExactMicroseconds)
          fail(dsec_[2].name, "row " + row + ": time " + std::to_string(us) +
                                  " us (with t_offset) beyond 2^33 s, where seconds in a double lose microseconds");
        e.t = double(us) / 1e6;  // as exact as the text: a correctly rounded quotient
        e.on = p_[cur_] == 1;
      } else {
        const double* r = &rows_[4 * cur_];
        x = r[0];
        y = r[1];
        e.t = r[2];
        e.on = r[3] > 0;
        if (!std::isfinite(e.t) || !(x >= 0 && x < 65536) || !(y >= 0 && y < 65536) || x != std::floor(x) ||
            y != std::floor(y))
          throw IoError(where() + ": not an event (x, y whole pixels, t finite)");
        if (r[3] != -1.0 && r[3] != 0.0 && r[3] != 1.0)
          throw IoError(where() + ": polarity " + std::to_string(r[3]) + " (expected -1 or 1; 0 is read as OFF)");
      }
      if ((width_ > 0 && x >= width_) || (height_ > 0 && y >= height_)) {
        outsideSensor(where(), x, y);
        continue;
      }
      e.x = float(x);
      e.y = float(y);
      admit(batch, e, where);
    }
  }

  std::unique_ptr<BinFile> raw_;  ///< the same file, for the header checks
  Hdf5Superblock superblock_;
  mutable std::set<std::uint64_t> checked_;  ///< addresses of the object headers checked
  H5Id file_;
  Layout layout_ = Layout::Dsec;
  std::uintmax_t file_bytes_ = 0;  ///< the file's size [bytes]
  mutable std::vector<unsigned char> chunk_stored_, chunk_decoded_;  ///< checkChunk's buffers
  Dataset dsec_[4];  ///< x, y, t, p
  Dataset mvsec_;
  std::int64_t t_offset_us_ = 0;
  hsize_t count_ = 0, next_ = 0, block_start_ = 0;
  std::size_t have_ = 0, cur_ = 0;
  std::vector<std::int64_t> x_, y_, t_, p_;  ///< a block of the DSEC datasets as stored (range-checked per row)
  std::vector<double> rows_;
};

}  // namespace

std::unique_ptr<EventReader> openHdf5(const std::string& path, const ReaderOptions& o) {
  return std::make_unique<Hdf5Reader>(path, o);
}

std::uint64_t hdf5LinkAddress(const std::string& path, const std::string& link) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  H5Id file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  H5L_info_t info;
  if (!file.valid() || H5Lget_info(file.get(), link.c_str(), &info, H5P_DEFAULT) < 0 || info.type != H5L_TYPE_HARD)
    throw IoError(path + ": " + link + ": no hard link");
  return std::uint64_t(info.u.address);
}

}  // namespace celc::detail
