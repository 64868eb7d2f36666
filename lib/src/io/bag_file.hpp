#pragma once
// Private: ROS 1 bag files (formats 2.0 and 1.2), read by celc itself.
//
// Record framing (both formats): uint32 header_len, header (fields: uint32
// len, "name=value"), uint32 data_len, data; the op field names the record.
//
// Format 2.0: "#ROSBAG V2.0\n", the bag header (op 0x03: index_pos,
// conn_count, chunk_count), chunks (op 0x05: compression none / bz2 / lz4,
// size = uncompressed bytes), each followed by its index data records (op
// 0x04: ver 1, conn, count; data: count x {uint32 sec, uint32 nsec, uint32
// offset of the message record inside the uncompressed chunk}); at index_pos
// the connection records (op 0x07: conn, topic; data: a header of topic, type,
// md5sum, message_definition, ...) and the chunk infos (op 0x06: ver,
// chunk_pos, start_time, end_time, count; data: count x {uint32 conn, uint32
// messages}). Inside a chunk: connection records and message data records
// (op 0x02: conn, time; data: the serialised message).
//
// Format 1.2: "#ROSBAG V1.2\n", the bag header (op 0x03: index_pos), message
// definition records (op 0x01: topic, md5, type, def) and message data records
// (op 0x02: topic, ...) without chunks, then at index_pos one index data record
// per topic (op 0x04: ver 0, topic, count; data: count x {uint32 sec, uint32
// nsec, uint64 file position of the topic's record}); the first entry of a
// topic points at its message definition record, which the message follows.
//
// Opening reads and checks the index: the bag header (index position zero =
// a bag never closed, beyond the end = a bag cut short: both point at
// `rosbag reindex`), every record of the index section within the file and of
// the op it must be, the counts the header states, every chunk's header
// (compression known, uncompressed size at most max_packet_bytes), every index
// data record's size, connection and entries. A chunk's records are checked
// whenever its bytes are at hand: every record inside the chunk, every
// message record naming a declared connection, and every index entry of the
// chunk on a message record of the entry's connection (the index decides which
// topic, hence which layout, a message is decoded as). An uncompressed chunk
// is at hand at open (its record headers are read from the file); a compressed
// one when a message of it is read, so that each chunk is decompressed once
// per pass over a topic. Format 1.2: every record of the file is walked at
// open and every index entry must point at a record's start.
#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "io/binary_file.hpp"

namespace celc::detail {

/// Appended to the errors of a damaged index or chunk.
inline constexpr const char* kReindexHint = " (`rosbag reindex FILE` rebuilds the index of a bag cut short)";

/// One connection: a 2.0 connection record of the index section, or a 1.2
/// topic with its message definition record.
struct BagConnection {
  std::uint32_t id = 0;
  std::string topic, type, md5sum, definition;
};

/// One message of the index.
struct BagEntry {
  std::uint64_t time_ns = 0;  ///< record time, sec * 1e9 + nsec
  std::uint64_t pos = 0;      ///< 2.0: offset of its record in the uncompressed chunk; 1.2: file position
  std::uint32_t chunk = 0;    ///< 2.0: the chunk's number (file order)
  std::uint32_t conn = 0;     ///< connection id
};

/// One record of an uncompressed chunk: where it starts, its op, its data and
/// (message data records) its connection.
struct ChunkRecord {
  std::uint32_t at = 0, data_at = 0, data_len = 0, conn = 0;
  std::uint8_t op = 0;
};

/// The chunk (2.0) or message (1.2) bytes a reader holds: one per stream, so
/// that reading one topic between another's messages keeps the other's chunk.
struct ChunkBuffer {
  std::vector<unsigned char> raw, plain;
  std::vector<ChunkRecord> records;  ///< plain's records (2.0)
  std::int64_t chunk = -1;           ///< the chunk plain holds (2.0), -1 = none
};

/// A message's serialised bytes; valid until its ChunkBuffer loads again.
struct BagMessage {
  const unsigned char* data = nullptr;
  std::size_t size = 0;
};

class BagFile {
 public:
  /// Opens `path` (format 2.0 or 1.2) and reads and checks its index as the top
  /// of this file says. Throws IoError "PATH: byte N: what" on damage, a
  /// chunk beyond `max_packet_bytes` or another format.
  BagFile(const std::string& path, std::size_t max_packet_bytes);
  BagFile(const BagFile&) = delete;
  BagFile& operator=(const BagFile&) = delete;

  int version() const { return version_; }  ///< 200 or 102
  const std::string& path() const { return f_.path(); }
  const std::vector<BagConnection>& connections() const { return connections_; }
  /// Chunks per compression (format 2.0).
  const std::map<std::string, int>& compressions() const { return compressions_; }
  /// Every index entry in file order (time 0 included).
  const std::vector<BagEntry>& index() const { return entries_; }
  /// The messages of the connections `conns` in record-time order (equal
  /// times in file order); entries at time 0 are left out.
  std::vector<BagEntry> messages(const std::vector<std::uint32_t>& conns) const;
  /// The bytes of `e`'s message. Loads its chunk into `buf` (read, decompressed
  /// and checked) unless buf holds it. Throws IoError on damage.
  BagMessage message(const BagEntry& e, ChunkBuffer& buf);

 private:
  /// One index data record of a chunk: where its entries are in the file and in entries_.
  struct IndexData {
    std::uint64_t data_at = 0;
    std::size_t first = 0;
    std::uint32_t count = 0, conn = 0;
  };
  struct Chunk {
    std::uint64_t at = 0, data_at = 0, data_len = 0;
    std::uint32_t size = 0;
    std::string compression;
    std::vector<IndexData> index;
  };
  using Bytes = std::function<const unsigned char*(std::size_t at, std::size_t n)>;

  void open20();
  void open12();
  void readDefinitions12();
  std::vector<std::uint64_t> readIndexSection(std::uint64_t index_pos, std::uint64_t header_end);
  void readChunk(std::uint64_t at, std::uint64_t index_pos);
  void readIndexData(std::uint32_t chunk, std::uint64_t from, std::uint64_t index_pos,
                     const std::vector<ChunkRecord>* records);
  std::vector<ChunkRecord> walkChunk(const Chunk& c, const Bytes& bytes) const;
  void checkEntries(const Chunk& c, const IndexData& ix, const std::vector<ChunkRecord>& records) const;
  void loadChunk(std::uint32_t chunk, ChunkBuffer& buf);
  BagMessage message12(const BagEntry& e, ChunkBuffer& buf);
  bool declared(std::uint32_t conn) const;

  BinFile f_;
  std::size_t max_packet_bytes_;
  int version_ = 0;
  std::vector<BagConnection> connections_;
  std::set<std::uint32_t> conn_ids_;  ///< connections_' ids
  std::vector<Chunk> chunks_;
  std::vector<BagEntry> entries_;
  std::map<std::string, int> compressions_;
  std::vector<std::uint64_t> records12_;  ///< 1.2: every record's start, ascending
  std::uint64_t index_pos12_ = 0;
};

}  // namespace celc::detail
