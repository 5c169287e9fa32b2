#include "snakehead/npz.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace snakehead {
namespace {

static_assert(sizeof(double) == 8, "IEEE doubles expected");

bool little_endian() {
  const std::uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t n = 0; n < 256; ++n) {
    std::uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = (c & 1U) ? 0xEDB88320U ^ (c >> 1) : c >> 1;
    t[n] = c;
  }
  return t;
}

void put16(std::string& s, std::uint16_t v) {
  s.push_back(static_cast<char>(v & 0xFF));
  s.push_back(static_cast<char>(v >> 8));
}
void put32(std::string& s, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) s.push_back(static_cast<char>((v >> (8 * k)) & 0xFF));
}

// Decode UTF-8 into code points (numpy's '<U' arrays hold UCS-4). Invalid bytes become U+FFFD.
std::vector<std::uint32_t> utf8_to_ucs4(const std::string& s) {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    int len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (len == 0 || i + len > s.size()) {
      out.push_back(0xFFFD);
      ++i;
      continue;
    }
    std::uint32_t cp = len == 1 ? c : c & (0x7F >> len);
    bool ok = true;
    for (int k = 1; k < len; ++k) {
      const unsigned char d = static_cast<unsigned char>(s[i + k]);
      if ((d >> 6) != 0x2) ok = false;
      cp = (cp << 6) | (d & 0x3F);
    }
    out.push_back(ok ? cp : 0xFFFD);
    i += ok ? len : 1;
  }
  return out;
}

}  // namespace

std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc) {
  static const std::array<std::uint32_t, 256> table = make_crc_table();
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint32_t c = crc ^ 0xFFFFFFFFU;
  for (std::size_t i = 0; i < size; ++i) c = table[(c ^ p[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFU;
}

void NpzWriter::add_raw(const std::string& name, const std::string& descr, const std::vector<std::int64_t>& shape,
                        const void* data, std::size_t size) {
  if (!little_endian()) throw std::runtime_error("NpzWriter supports little-endian machines only");
  std::string shape_s = "(";
  for (std::size_t k = 0; k < shape.size(); ++k) shape_s += std::to_string(shape[k]) + (shape.size() == 1 ? "," : k + 1 < shape.size() ? ", " : "");
  shape_s += ")";
  std::string header = "{'descr': '" + descr + "', 'fortran_order': False, 'shape': " + shape_s + ", }";
  // Magic (6) + version (2) + header length (2) + header, padded with spaces to a multiple of 64 and
  // ending in a newline, as NumPy writes it.
  const std::size_t total = 10 + header.size() + 1;
  header.append((64 - total % 64) % 64, ' ');
  header.push_back('\n');
  if (header.size() > 65535) throw std::runtime_error("NPY header too long for " + name);
  std::string content("\x93NUMPY\x01\x00", 8);
  put16(content, static_cast<std::uint16_t>(header.size()));
  content += header;
  content.append(static_cast<const char*>(data), size);
  for (const auto& e : entries_)
    if (e.name == name + ".npy") throw std::invalid_argument("duplicate npz entry " + name);
  entries_.push_back({name + ".npy", std::move(content)});
}

namespace {
template <class T>
std::size_t checked_count(const std::vector<T>& data, const std::vector<std::int64_t>& shape, const std::string& name) {
  std::int64_t n = 1;
  for (auto s : shape) n *= s;
  if (n != static_cast<std::int64_t>(data.size()))
    throw std::invalid_argument("npz entry " + name + ": data size does not match its shape");
  return data.size() * sizeof(T);
}
}  // namespace

void NpzWriter::add_f64(const std::string& name, const std::vector<double>& data, std::vector<std::int64_t> shape) {
  add_raw(name, "<f8", shape, data.data(), checked_count(data, shape, name));
}
void NpzWriter::add_i64(const std::string& name, const std::vector<std::int64_t>& data,
                        std::vector<std::int64_t> shape) {
  add_raw(name, "<i8", shape, data.data(), checked_count(data, shape, name));
}
void NpzWriter::add_i32(const std::string& name, const std::vector<std::int32_t>& data,
                        std::vector<std::int64_t> shape) {
  add_raw(name, "<i4", shape, data.data(), checked_count(data, shape, name));
}
void NpzWriter::add_u64(const std::string& name, const std::vector<std::uint64_t>& data,
                        std::vector<std::int64_t> shape) {
  add_raw(name, "<u8", shape, data.data(), checked_count(data, shape, name));
}
void NpzWriter::add_u8(const std::string& name, const std::vector<std::uint8_t>& data,
                       std::vector<std::int64_t> shape) {
  add_raw(name, "|u1", shape, data.data(), checked_count(data, shape, name));
}
void NpzWriter::add_bool(const std::string& name, bool value) {
  const unsigned char b = value ? 1 : 0;
  add_raw(name, "|b1", {}, &b, 1);
}
void NpzWriter::add_string(const std::string& name, const std::string& utf8) {
  std::vector<std::uint32_t> cps = utf8_to_ucs4(utf8);
  if (cps.empty()) cps.push_back(0);  // numpy has no '<U0'; one NUL reads back as ''
  add_raw(name, "<U" + std::to_string(cps.size()), {}, cps.data(), cps.size() * 4);
}

std::string NpzWriter::bytes() const {
  // Zip with stored (uncompressed) entries: local header + data per entry, then the central
  // directory and its end record. Sizes stay below 4 GiB, so no zip64.
  const std::uint16_t kTime = 0, kDate = (1 << 5) | 1;  // 1980-01-01 00:00: reproducible bytes
  std::string out, central;
  for (const auto& e : entries_) {
    if (e.content.size() >= 0xFFFFFFFFULL || out.size() >= 0xFFFFFFFFULL)
      throw std::runtime_error("npz too large (zip64 not supported)");
    const std::uint32_t crc = crc32(e.content.data(), e.content.size());
    const auto size = static_cast<std::uint32_t>(e.content.size());
    const auto offset = static_cast<std::uint32_t>(out.size());
    put32(out, 0x04034b50);
    put16(out, 20);  // version needed
    put16(out, 0);   // flags
    put16(out, 0);   // method: stored
    put16(out, kTime);
    put16(out, kDate);
    put32(out, crc);
    put32(out, size);
    put32(out, size);
    put16(out, static_cast<std::uint16_t>(e.name.size()));
    put16(out, 0);  // extra length
    out += e.name;
    out += e.content;

    put32(central, 0x02014b50);
    put16(central, 20);  // version made by
    put16(central, 20);  // version needed
    put16(central, 0);
    put16(central, 0);
    put16(central, kTime);
    put16(central, kDate);
    put32(central, crc);
    put32(central, size);
    put32(central, size);
    put16(central, static_cast<std::uint16_t>(e.name.size()));
    put16(central, 0);  // extra
    put16(central, 0);  // comment
    put16(central, 0);  // disk
    put16(central, 0);  // internal attributes
    put32(central, 0);  // external attributes
    put32(central, offset);
    central += e.name;
  }
  const auto cd_offset = static_cast<std::uint32_t>(out.size());
  out += central;
  put32(out, 0x06054b50);
  put16(out, 0);
  put16(out, 0);
  put16(out, static_cast<std::uint16_t>(entries_.size()));
  put16(out, static_cast<std::uint16_t>(entries_.size()));
  put32(out, static_cast<std::uint32_t>(central.size()));
  put32(out, cd_offset);
  put16(out, 0);  // comment length
  return out;
}

namespace {

// A new file beside `path`, created by this call (O_EXCL) with the permissions a plain open would give.
int create_temporary(const std::string& path, std::string& tmp) {
  static std::atomic<unsigned> counter{0};
  for (int attempt = 0;; ++attempt) {
    tmp = path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) return fd;
    if (errno != EEXIST || attempt > 100) throw std::runtime_error("cannot write '" + path + "': " + std::strerror(errno));
  }
}

}  // namespace

void check_output_path(const std::string& path) {
  if (path.empty() || path.find('\0') != std::string::npos)
    throw std::runtime_error("the output path is empty or holds a NUL character");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))  // renaming over it would replace a device, a FIFO...
    throw std::runtime_error("cannot write '" + path + "': it exists and is not a regular file");
  std::string tmp;
  ::close(create_temporary(path, tmp));
  ::unlink(tmp.c_str());
}

void NpzWriter::write(const std::string& path) const {
  const std::string data = bytes();
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw std::runtime_error("cannot write '" + path + "': it exists and is not a regular file");
  // Write to a new file beside the target, then rename it over the target: a failed or interrupted write
  // (disk full, file-size limit, a signal) leaves any old file as it was and never a truncated one.
  std::string tmp;
  int fd = create_temporary(path, tmp);
  auto fail = [&](const char* step) {
    const std::string why = std::strerror(errno);
    if (fd >= 0) ::close(fd);
    ::unlink(tmp.c_str());
    throw std::runtime_error("cannot write '" + path + "' (" + step + "): " + why);
  };
  for (std::size_t done = 0; done < data.size();) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = EIO;
      fail("write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) fail("fsync");  // a full disk may only say so here
  const int closed = ::close(fd);
  fd = -1;
  if (closed != 0) fail("close");
  if (std::rename(tmp.c_str(), path.c_str()) != 0) fail("rename");
}

}  // namespace snakehead
