// A minimal writer of NumPy .npz files: NPY version 1.0 arrays in an uncompressed (stored) zip,
// which numpy.load reads with allow_pickle=False. Little-endian data only (the NPY header says so).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace snakehead {

// CRC-32 (IEEE 802.3, the zip checksum) of `size` bytes, continuing from `crc` (0 to start).
std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc = 0);

// Throws std::runtime_error unless a file can be written at `path` by NpzWriter::write: its directory takes
// new files, and `path` does not exist or is a regular file. (Tried by creating and removing a file there.)
void check_output_path(const std::string& path);

class NpzWriter {
 public:
  // Arrays in C order; `shape` empty for a 0-d array (a scalar).
  void add_f64(const std::string& name, const std::vector<double>& data, std::vector<std::int64_t> shape);
  void add_i64(const std::string& name, const std::vector<std::int64_t>& data, std::vector<std::int64_t> shape);
  void add_i32(const std::string& name, const std::vector<std::int32_t>& data, std::vector<std::int64_t> shape);
  void add_u64(const std::string& name, const std::vector<std::uint64_t>& data, std::vector<std::int64_t> shape);
  void add_u8(const std::string& name, const std::vector<std::uint8_t>& data, std::vector<std::int64_t> shape);
  void add_bool(const std::string& name, bool value);
  void add_scalar(const std::string& name, double value) { add_f64(name, {value}, {}); }
  void add_scalar(const std::string& name, std::int64_t value) { add_i64(name, {value}, {}); }
  // A 0-d unicode string array (numpy '<U<n>'); the text must be UTF-8.
  void add_string(const std::string& name, const std::string& utf8);

  // The zip file's bytes, and writing them (throws std::runtime_error when the file cannot be written).
  // The file is written under a temporary name in the same directory and renamed over `path`, so a failed
  // write leaves an existing file intact and no partial file. (A process that does not ignore SIGXFSZ is
  // killed by a write beyond its file-size limit before it can clean up: ignore it, as Python does.)
  std::string bytes() const;
  void write(const std::string& path) const;

 private:
  void add_raw(const std::string& name, const std::string& descr, const std::vector<std::int64_t>& shape,
               const void* data, std::size_t size);
  struct Entry {
    std::string name;  // "x.npy"
    std::string content;
  };
  std::vector<Entry> entries_;
};

}  // namespace snakehead
