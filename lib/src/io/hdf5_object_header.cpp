#include "io/hdf5_object_header.hpp"

#include <cstring>
#include <set>

namespace celc::detail {
namespace {

constexpr char kSignature[] = "\x89HDF\r\n\x1a\n";
constexpr int kContinuation = 0x10;
constexpr int kLayout = 0x08;       ///< a dataset's storage: compact, contiguous or chunked (and its chunk's sizes)
constexpr int kSymbolTable = 0x11;  ///< an old-style group: its B-tree's and local heap's addresses
constexpr int kBtreeK = 0x13;       ///< superblock extension: the B-trees' K values
constexpr std::size_t kMaxChunks = 4096;  ///< chunks walked per header (a loop of continuations ends here)

/// Little-endian unsigned integer of `n` (1-8) bytes.
std::uint64_t loadUnsigned(const unsigned char* p, int n) {
  std::uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

/// Bytes [at, at + n) of the file; throws when they are not all there.
std::vector<unsigned char> bytesAt(BinFile& file, std::uint64_t at, std::uint64_t n, const std::string& what) {
  if (at > file.size() || n > file.size() - at)
    file.fail(at, what + ": " + std::to_string(n) + " bytes from here pass the file's end (" +
                      std::to_string(file.size()) + " bytes)");
  std::vector<unsigned char> b(static_cast<std::size_t>(n));
  file.seek(at);
  file.readExact(b.data(), b.size(), what.c_str());
  return b;
}

/// The messages in `chunk` (the bytes of one chunk's message area, starting at
/// absolute byte `start`) of a version 1 or 2 header.
void collectMessages(const std::vector<unsigned char>& chunk, std::uint64_t start, int header_version,
                     bool creation_order, std::vector<Hdf5Message>& out) {
  const std::size_t head = header_version == 1 ? 8 : (creation_order ? 6 : 4);
  std::size_t p = 0;
  while (p + head <= chunk.size()) {
    Hdf5Message m;
    if (header_version == 1) {
      m.type = int(loadUnsigned(&chunk[p], 2));
      m.size = loadUnsigned(&chunk[p + 2], 2);
    } else {
      m.type = chunk[p];
      m.size = loadUnsigned(&chunk[p + 1], 2);
    }
    m.data_byte = start + p + head;
    if (p + head + m.size > chunk.size()) return;  // a damaged message: the library reports it
    out.push_back(m);
    p += head + std::size_t(m.size);
  }
}

/// The local heap of an old-style group (the names of its links): "HEAP",
/// version 0, 3 reserved bytes, the data segment's size (a length), the free
/// list's offset (a length), the data segment's address. Its data segment must
/// lie inside the file: the library sizes its buffer from that field; and its
/// free list must end inside it.
void checkLocalHeap(BinFile& file, const Hdf5Superblock& sb, std::uint64_t address, const std::string& what) {
  const std::uint64_t in_file = file.size() - sb.base;
  const std::size_t o = std::size_t(sb.offset_bytes), l = std::size_t(sb.length_bytes);
  if (address > in_file) file.fail(sb.base, what + ": local heap at address " + std::to_string(address) +
                                                ", beyond the file's end (" + std::to_string(file.size()) + " bytes)");
  const std::vector<unsigned char> h = bytesAt(file, sb.base + address, 8 + 2 * l + o, what + ": local heap");
  if (std::memcmp(h.data(), "HEAP", 4) != 0) file.fail(sb.base + address, what + ": local heap without its HEAP signature");
  const std::uint64_t bytes = loadUnsigned(&h[8], sb.length_bytes);
  const std::uint64_t data = loadUnsigned(&h[8 + 2 * l], sb.offset_bytes);
  if (data > in_file || bytes > in_file - data)
    file.fail(sb.base + address + 8, what + ": local heap data of " + std::to_string(bytes) + " bytes at address " +
                                         std::to_string(data) + " passes the file's end (" +
                                         std::to_string(file.size()) + " bytes)");
  // The free list: blocks in the data segment, each holding the next block's
  // offset and its own size (two lengths); offset 1 or all ones ends it. The
  // library follows it without a bound, allocating a node per block: a list
  // that loops takes all the memory there is. It holds at most one block per
  // 2 lengths of the segment.
  const std::uint64_t end_marker = sb.length_bytes >= 8 ? ~0ull : (1ull << (8 * sb.length_bytes)) - 1;
  std::uint64_t block = loadUnsigned(&h[8 + l], sb.length_bytes);
  for (std::uint64_t count = 0; block != 1 && block != end_marker; ++count) {
    if (count > bytes / (2 * l))
      file.fail(sb.base + address + 8 + l, what + ": local heap free list of more than " +
                                               std::to_string(count) + " blocks in " + std::to_string(bytes) +
                                               " bytes: it loops");
    if (block >= bytes || 2 * l > bytes - block)
      file.fail(sb.base + address + 8 + l, what + ": local heap free block at offset " + std::to_string(block) +
                                               " outside its " + std::to_string(bytes) + "-byte data segment");
    const std::vector<unsigned char> b = bytesAt(file, sb.base + data + block, 2 * l, what + ": local heap free block");
    block = loadUnsigned(b.data(), sb.length_bytes);
  }
}

/// A chunked dataset's index in layout versions 1-3: a version 1 B-tree of
/// node type 1. A node is "TREE", its type, its level, the entries it uses
/// (u16), its left and right siblings' addresses, then 2K + 1 keys (chunk size
/// u32, filter mask u32, an offset u64 per dimension of the layout's rank)
/// alternating with 2K child addresses: chunk nodes one level down, or at
/// level 0 the chunks. The library reads each node whole, sized by K, before
/// it looks at it. Each node is visited once; a tree has at most one node per
/// node size of the file.
void checkChunkBtree(BinFile& file, const Hdf5Superblock& sb, std::uint64_t root, std::size_t rank,
                     const std::string& what) {
  if (hdf5Undefined(sb, root)) return;  // no chunk written yet
  const std::uint64_t o = std::uint64_t(sb.offset_bytes), k = std::uint64_t(sb.chunk_btree_k);
  const std::uint64_t key = 8 + 8 * std::uint64_t(rank);
  const std::uint64_t node_bytes = 8 + 2 * o + 2 * k * o + (2 * k + 1) * key;
  const std::uint64_t in_file = file.size() - std::min(file.size(), sb.base);
  const std::string tree = what + ": chunk index";
  struct Node {
    std::uint64_t address;
    int level;  // expected; -1 for the root
  };
  std::vector<Node> todo{{root, -1}};
  std::set<std::uint64_t> seen;
  for (std::size_t n = 0; n < todo.size(); ++n) {
    const Node node = todo[n];
    if (node.address > in_file || node_bytes > in_file - node.address)
      file.fail(sb.base, tree + ": a node of " + std::to_string(node_bytes) + " bytes at address " +
                             std::to_string(node.address) + " passes the file's end (" + std::to_string(file.size()) +
                             " bytes)");
    if (!seen.insert(node.address).second) continue;
    if (seen.size() > in_file / node_bytes)
      file.fail(sb.base + node.address, tree + ": more nodes than the file holds (it loops)");
    const std::uint64_t at = sb.base + node.address;
    const std::vector<unsigned char> b = bytesAt(file, at, node_bytes, tree);
    if (std::memcmp(b.data(), "TREE", 4) != 0) file.fail(at, tree + ": a node without its TREE signature");
    if (b[4] != 1) file.fail(at + 4, tree + ": a node of type " + std::to_string(b[4]) + ", not a chunk node (1)");
    const int level = b[5];
    if (node.level >= 0 && level != node.level)
      file.fail(at + 5, tree + ": a node at level " + std::to_string(level) + " under one at level " +
                            std::to_string(node.level + 1));
    const std::uint64_t entries = loadUnsigned(&b[6], 2);
    if (entries > 2 * k)
      file.fail(at + 6, tree + ": a node using " + std::to_string(entries) + " entries, more than 2K = " +
                            std::to_string(2 * k));
    for (std::uint64_t e = 0; e < entries; ++e) {
      const std::uint64_t child_at = 8 + 2 * o + (e + 1) * key + e * o;
      const std::uint64_t child = loadUnsigned(&b[child_at], sb.offset_bytes);
      if (child >= in_file)
        file.fail(at + child_at, tree + ": child " + std::to_string(e) + " at address " + std::to_string(child) +
                                     ", beyond the file's end (" + std::to_string(file.size()) + " bytes)");
      if (level > 0) todo.push_back({child, level - 1});
    }
  }
}

/// A chunked layout's chunk sizes must be positive and its rank (the dataset's
/// plus one, for the element size) at least 2: the library divides the
/// dataset's sizes by them. Layout message versions 1-2: version, rank, class,
/// 5 reserved, an address unless compact, then rank u32 sizes; version 3:
/// version, class, then for chunked rank, address, rank u32 sizes; version 4:
/// version, class, then for chunked flags, rank, the sizes' width (1-8), the sizes.
void checkLayout(BinFile& file, const Hdf5Superblock& sb, const Hdf5Message& m, const std::string& what) {
  if (m.size < 2) return;  // the library reports a message this short
  const std::vector<unsigned char> d = bytesAt(file, m.data_byte, m.size, what);
  const int version = d[0];
  const std::size_t o = std::size_t(sb.offset_bytes);
  std::size_t first = 0, rank = 0, width = 4;
  std::size_t index = 0;  // the chunk B-tree's address (layout versions 1-3)
  if (version == 1 || version == 2) {
    if (d.size() < 8 || d[2] != 2) return;
    rank = d[1];
    index = 8;
    first = 8 + o;
  } else if (version == 3) {
    if (d[1] != 2 || d.size() < 3) return;
    rank = d[2];
    index = 3;
    first = 3 + o;
  } else if (version == 4) {
    if (d[1] != 2 || d.size() < 5) return;
    rank = d[3];
    width = d[4];
    first = 5;
    if (width < 1 || width > 8) file.fail(m.data_byte + 4, what + ": chunk sizes of " + std::to_string(width) + " bytes");
  } else {
    return;
  }
  // the rank counts the dataset's dimensions and the element size: a chunked dataset has at least one
  if (rank < 2) file.fail(m.data_byte, what + ": a chunked layout of rank " + std::to_string(rank) + " (at least 2)");
  for (std::size_t k = 0; k < rank; ++k) {
    const std::size_t at = first + k * width;
    if (at + width > d.size()) file.fail(m.data_byte, what + ": a chunked layout message too short for its rank");
    if (loadUnsigned(&d[at], int(width)) == 0)
      file.fail(m.data_byte + at, what + ": chunk size 0 in dimension " + std::to_string(k));
  }
  if (index > 0) checkChunkBtree(file, sb, loadUnsigned(&d[index], sb.offset_bytes), rank, what);
}

}  // namespace

bool hdf5Undefined(const Hdf5Superblock& sb, std::uint64_t address) {
  const std::uint64_t ones = sb.offset_bytes >= 8 ? ~0ull : (std::uint64_t(1) << (8 * sb.offset_bytes)) - 1;
  return address == ones;
}

void readHdf5ChunkBtreeK(BinFile& file, Hdf5Superblock& sb, const std::vector<Hdf5Message>& extension) {
  // B-tree K message: version, chunk K (u16), group internal K (u16), group leaf K (u16).
  for (const Hdf5Message& m : extension) {
    if (m.type != kBtreeK || m.size < 3) continue;
    const std::vector<unsigned char> d = bytesAt(file, m.data_byte, 3, "the superblock extension's B-tree K message");
    sb.chunk_btree_k = int(loadUnsigned(&d[1], 2));
    if (sb.chunk_btree_k == 0) file.fail(m.data_byte + 1, "the superblock extension: a chunk B-tree K of 0");
  }
}

Hdf5Superblock readHdf5Superblock(BinFile& file) {
  Hdf5Superblock sb;
  std::uint64_t at = 0;
  for (;; at = at == 0 ? 512 : at * 2) {
    if (at + 8 > file.size()) file.fail(0, "no HDF5 superblock signature at byte 0, 512, 1024, ...");
    unsigned char sig[8];
    file.seek(at);
    file.readExact(sig, 8, "HDF5 signature");
    if (std::memcmp(sig, kSignature, 8) == 0) break;
  }
  sb.base = at;
  const std::vector<unsigned char> h = bytesAt(file, at, std::min<std::uint64_t>(file.size() - at, 256), "superblock");
  if (h.size() < 16) file.fail(at, "truncated HDF5 superblock");
  sb.version = h[8];
  std::size_t addresses = 0;  // offset of the base address field
  if (sb.version == 0 || sb.version == 1) {
    sb.offset_bytes = h[13];
    sb.length_bytes = h[14];
    addresses = sb.version == 0 ? 24 : 28;
  } else if (sb.version == 2 || sb.version == 3) {
    sb.offset_bytes = h[9];
    sb.length_bytes = h[10];
    addresses = 12;
  } else {
    file.fail(at + 8, "HDF5 superblock version " + std::to_string(sb.version) + " (this reader knows 0-3)");
  }
  for (int n : {sb.offset_bytes, sb.length_bytes})
    if (n != 2 && n != 4 && n != 8)
      file.fail(at + 9, "HDF5 addresses or lengths of " + std::to_string(n) + " bytes (2, 4 or 8 are read)");
  const std::size_t o = std::size_t(sb.offset_bytes);
  // v0/1: base, free space, end of file, driver info, then the root entry (link name offset, header address);
  // v2/3: base, extension, end of file, root header address.
  const std::size_t root_field = sb.version <= 1 ? addresses + 5 * o : addresses + 3 * o;
  if (root_field + o > h.size()) file.fail(at, "truncated HDF5 superblock");
  sb.root_header = loadUnsigned(&h[root_field], sb.offset_bytes);
  if (sb.version == 1) {  // after the group K values and the consistency flags
    sb.chunk_btree_k = int(loadUnsigned(&h[24], 2));
    if (sb.chunk_btree_k == 0) file.fail(at + 24, "HDF5 superblock: a chunk B-tree K of 0");
  }
  if (sb.version >= 2) sb.extension = loadUnsigned(&h[addresses + o], sb.offset_bytes);
  if (sb.version <= 1 || hdf5Undefined(sb, sb.extension)) sb.extension = ~0ull;
  return sb;
}

std::vector<Hdf5Message> checkHdf5ObjectHeader(BinFile& file, const Hdf5Superblock& sb, std::uint64_t address,
                                               const std::string& object) {
  const std::string what = "object header of " + object;
  if (address > file.size() - std::min(file.size(), sb.base))
    file.fail(sb.base, what + " at address " + std::to_string(address) + ", beyond the file's end (" +
                           std::to_string(file.size()) + " bytes)");
  const std::uint64_t at = sb.base + address;
  const std::vector<unsigned char> prefix = bytesAt(file, at, std::min<std::uint64_t>(file.size() - at, 64), what);
  int version = 0;
  bool creation_order = false;
  std::uint64_t first = 0, size = 0;  // message area of chunk 0: absolute byte, bytes
  if (prefix.size() >= 16 && prefix[0] == 1) {
    version = 1;
    size = loadUnsigned(&prefix[8], 4);
    first = at + 16;
  } else if (prefix.size() >= 7 && std::memcmp(prefix.data(), "OHDR", 4) == 0 && prefix[4] == 2) {
    version = 2;
    const unsigned flags = prefix[5];
    creation_order = (flags & 0x04) != 0;
    std::size_t p = 6 + ((flags & 0x20) ? 16 : 0) + ((flags & 0x10) ? 4 : 0);
    const int width = 1 << (flags & 0x03);
    if (p + std::size_t(width) > prefix.size()) file.fail(at, what + ": truncated prefix");
    size = loadUnsigned(&prefix[p], width);
    first = at + p + std::size_t(width);
  } else if (prefix.size() < 16) {
    file.fail(at, what + ": the file ends inside it (truncated?)");
  } else {
    file.fail(at, what + ": neither a version 1 nor a version 2 (OHDR) object header");
  }
  std::vector<Hdf5Message> messages;
  std::set<std::uint64_t> seen{at};
  struct Chunk {
    std::uint64_t start, bytes;
  };
  std::vector<Chunk> todo{{first, size}};
  for (std::size_t k = 0; k < todo.size(); ++k) {
    if (k >= kMaxChunks) file.fail(at, what + ": more than " + std::to_string(kMaxChunks) + " chunks");
    const Chunk c = todo[k];
    const std::uint64_t checksum = version == 2 ? 4 : 0;
    if (c.bytes > file.size() || c.start > file.size() - c.bytes || file.size() - c.start - c.bytes < checksum)
      file.fail(c.start, what + ": a chunk of " + std::to_string(c.bytes) + " bytes passes the file's end (" +
                             std::to_string(file.size()) + " bytes)");
    const std::size_t before = messages.size();
    collectMessages(bytesAt(file, c.start, c.bytes, what), c.start, version, creation_order, messages);
    for (std::size_t i = before; i < messages.size(); ++i) {
      const Hdf5Message& m = messages[i];
      const std::size_t o = std::size_t(sb.offset_bytes), l = std::size_t(sb.length_bytes);
      if (m.type == kSymbolTable) {
        if (m.size < 2 * o) file.fail(m.data_byte, what + ": a symbol table message of " + std::to_string(m.size) + " bytes");
        checkLocalHeap(file, sb, loadUnsigned(bytesAt(file, m.data_byte + o, o, what).data(), sb.offset_bytes), what);
      }
      if (m.type == kLayout) checkLayout(file, sb, m, what);
      if (m.type != kContinuation) continue;
      if (m.size < o + l) file.fail(m.data_byte, what + ": a continuation message of " + std::to_string(m.size) + " bytes");
      const std::vector<unsigned char> d = bytesAt(file, m.data_byte, o + l, what);
      const std::uint64_t chunk_address = loadUnsigned(d.data(), sb.offset_bytes);
      const std::uint64_t chunk_bytes = loadUnsigned(d.data() + o, sb.length_bytes);
      const std::uint64_t in_file = file.size() - sb.base;
      const std::uint64_t sig = version == 2 ? 4 : 0;
      if (chunk_address > in_file || chunk_bytes > in_file - chunk_address || chunk_bytes < sig + checksum)
        file.fail(m.data_byte, what + ": continuation chunk of " + std::to_string(chunk_bytes) + " bytes at address " +
                                   std::to_string(chunk_address) + " passes the file's end (" +
                                   std::to_string(file.size()) + " bytes)");
      const std::uint64_t chunk_at = sb.base + chunk_address;
      if (!seen.insert(chunk_at).second) continue;
      if (version == 2 && std::memcmp(bytesAt(file, chunk_at, 4, what).data(), "OCHK", 4) != 0)
        file.fail(chunk_at, what + ": continuation chunk without its OCHK signature");
      todo.push_back({chunk_at + sig, chunk_bytes - sig - checksum});
    }
  }
  return messages;
}

}  // namespace celc::detail
