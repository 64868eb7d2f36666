#pragma once
// Checks of HDF5 object headers made before the HDF5 C library reads them.
// The library (1.10.8) uses fields of the file before it compares them with
// the file's end, and no API call can look at them first (docs/decisions.md):
//  - a continuation message's length sizes a metadata-cache buffer: 4 GB
//    allocated for a 14 KB file;
//  - an old-style group's local heap sizes its data segment the same way
//    (88 TB), a heap at the undefined address is read through NULL, and a
//    free list that loops is followed until memory runs out;
//  - a chunked layout of rank 0 is divided by (SIGFPE in H5Dopen2);
//  - a chunk B-tree node is read whole from its address: one that passes the
//    file's end, or that is not a chunk node, is copied from NULL (SIGSEGV in
//    H5Dget_num_chunks).
// The reader checks every object header it is about to open with these
// functions: every chunk of the header, its local heap and its layout.
//
// Format facts (HDF5 file format specification, version 3.0): the superblock
// sits at byte 0, 512, 1024, 2048, ... and every file address is relative to
// it; object header version 1 is a 16-byte prefix (version 1, message count,
// reference count, chunk size) followed by 8-byte message headers (type u16,
// size u16, flags, 3 reserved); version 2 starts with "OHDR" and its
// continuation chunks with "OCHK", message headers are type u8, size u16,
// flags and an optional u16 creation order, and every chunk ends with a
// 4-byte checksum. A continuation message (type 0x10) holds a chunk's address
// and length; a layout message (type 0x08) a chunked dataset's chunk sizes,
// by which the library divides; a symbol table message (type 0x11) the addresses of an old-style
// group's B-tree and local heap, whose data segment the library reads whole.
#include <cstdint>
#include <string>
#include <vector>

#include "io/binary_file.hpp"

namespace celc::detail {

/// What the checks need from the superblock.
struct Hdf5Superblock {
  std::uint64_t base = 0;           ///< byte of the superblock: addresses are relative to it
  int version = 0;                  ///< 0-3
  int offset_bytes = 8;             ///< size of a file address [bytes]
  int length_bytes = 8;             ///< size of a length [bytes]
  std::uint64_t root_header = 0;    ///< address of the root group's object header
  std::uint64_t extension = ~0ull;  ///< address of the superblock extension's header (~0: none)
  /// Chunk B-trees' K: a node holds up to 2K chunks (the library's default
  /// 32; superblock version 1 or the extension's B-tree K message say otherwise).
  int chunk_btree_k = 32;
};

/// One message of an object header, as found in the file.
struct Hdf5Message {
  int type = 0;
  std::uint64_t data_byte = 0;  ///< absolute byte of its data
  std::uint64_t size = 0;       ///< its data [bytes]
};

/// Finds and reads the superblock; throws IoError naming the file and byte
/// when there is none or its fields cannot be used.
Hdf5Superblock readHdf5Superblock(BinFile& file);

/// True for the all-ones "undefined address" of `sb`'s address size.
bool hdf5Undefined(const Hdf5Superblock& sb, std::uint64_t address);

/// Takes the chunk B-trees' K from the superblock extension's messages (a B-tree
/// K message, type 0x13), where there is one; a K of 0 throws IoError.
void readHdf5ChunkBtreeK(BinFile& file, Hdf5Superblock& sb, const std::vector<Hdf5Message>& extension);

/// Checks the object header of `object` at file address `address`: its
/// prefix, every chunk it reaches through continuation messages, and an
/// old-style group's local heap (its symbol table message) must lie inside the
/// file; a chunked layout's chunk sizes must be positive, and every node of its
/// chunk index (a version 1 B-tree, layout versions 1-3) must lie in the file,
/// be a chunk node one level above its children and hold at most 2K entries.
/// Throws IoError "FILE: byte N: object header of OBJECT: ...".
/// Returns the messages of every chunk (in chunk order).
std::vector<Hdf5Message> checkHdf5ObjectHeader(BinFile& file, const Hdf5Superblock& sb, std::uint64_t address,
                                               const std::string& object);

}  // namespace celc::detail
