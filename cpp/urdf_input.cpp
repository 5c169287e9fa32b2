#include "snakehead/urdf_input.hpp"

#include <console_bridge/console.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <thread>
#include <vector>

#include "snakehead/limits.hpp"
#include "snakehead/model.hpp"

namespace snakehead {
namespace {

// ---------------------------------------------------------------------------------------------------------
// Reading a file: a regular file of bounded size, opened without blocking (a FIFO would wait for a writer).

std::string file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// ---------------------------------------------------------------------------------------------------------
// The document scan. It reads the text the way TinyXML 2.6's parser does (tinyxmlparser.cpp: Document,
// Element, ReadValue, Attribute, Text, Comment, Unknown, Declaration), only counting the open elements
// instead of building nodes, in a loop instead of recursion. Where TinyXML would stop or fail, the scan
// stops (what follows is never parsed); where TinyXML's reading depends on details the scan does not
// follow (its encoding mode, malformed character references whose ';' search can skip over markup), the
// document is rejected instead, so the depth counted is never below the depth TinyXML reaches.

class DocumentScan {
 public:
  explicit DocumentScan(const std::string& xml) : text_(xml), p_(xml.c_str()) {}

  void run() {
    check_encoding();
    const char* p = p_;
    if (starts_with(p, "\xEF\xBB\xBF")) p += 3;  // a byte order mark
    int depth = 0;
    p = skip_space(p);
    while (p && *p) {
      if (depth > 0 && *p != '<') {  // an element's text
        p = text(p);
      } else if (depth > 0 && p[1] == '/') {  // the element's end tag
        p = end_tag(p);
        if (p) --depth;
      } else if (*p != '<') {  // text outside the root: TinyXML stops reading the document here
        return;
      } else if (starts_with_nocase(p, "<?xml")) {
        p = declaration(p + 5);
      } else if (starts_with(p, "<!--")) {
        p = skip_past(p + 4, "-->");
      } else if (starts_with(p, "<![CDATA[")) {
        p = skip_past(p + 9, "]]>");
      } else if (is_name_start(p[1])) {
        bool empty = false;
        p = start_tag(p, empty);
        if (p && !empty && ++depth > limits::kMaxUrdfDepth)
          fail(p, "elements are nested more than " + std::to_string(limits::kMaxUrdfDepth) +
                      " levels deep (URDF needs about six)");
      } else {  // <!DOCTYPE ...>, <?pi ...>, stray markup: TinyXML skips to the next '>'
        p = skip_past(p + 1, ">");
      }
      if (p) p = skip_space(p);
    }
  }

 private:
  [[noreturn]] void fail(const char* at, const std::string& what) const {
    const long line = 1 + std::count(text_.c_str(), std::max(at, text_.c_str()), '\n');
    throw InputError("malformed URDF (line " + std::to_string(line) + "): " + what);
  }

  // Whole-document checks: no NUL (TinyXML would silently stop there), UTF-8 (in its UTF-8 mode TinyXML
  // steps over a multi-byte character by its lead byte alone), no U+FEFF/U+FFFE/U+FFFF after the start
  // (TinyXML's UTF-8 mode reads them as white space, its other mode as letters).
  void check_encoding() const {
    if (text_.size() > limits::kMaxUrdfBytes)
      throw InputError("the URDF is " + std::to_string(text_.size()) + " bytes; at most " +
                       std::to_string(limits::kMaxUrdfBytes) + " are read");
    const auto* s = reinterpret_cast<const unsigned char*>(text_.data());
    const std::size_t n = text_.size();
    for (std::size_t i = 0; i < n;) {
      const unsigned char c = s[i];
      if (c == 0) fail(text_.c_str() + i, "a NUL byte in the text");
      std::size_t len = c < 0x80 ? 1 : (c >= 0xC2 && c <= 0xDF) ? 2 : (c >= 0xE0 && c <= 0xEF) ? 3
                                                             : (c >= 0xF0 && c <= 0xF4) ? 4 : 0;
      bool ok = len > 0 && i + len <= n;
      for (std::size_t k = 1; ok && k < len; ++k) ok = (s[i + k] & 0xC0) == 0x80;
      if (ok && len >= 3) {  // overlong forms and surrogates
        const unsigned char d = s[i + 1];
        ok = !(c == 0xE0 && d < 0xA0) && !(c == 0xED && d > 0x9F) && !(c == 0xF0 && d < 0x90) &&
             !(c == 0xF4 && d > 0x8F);
      }
      if (!ok) fail(text_.c_str() + i, "the text is not UTF-8");
      if (len == 3 && c == 0xEF && i > 0 &&
          ((s[i + 1] == 0xBB && s[i + 2] == 0xBF) || (s[i + 1] == 0xBF && (s[i + 2] == 0xBE || s[i + 2] == 0xBF))))
        fail(text_.c_str() + i, "a byte order mark or U+FFFE/U+FFFF inside the text");
      i += len;
    }
  }

  static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
  }
  static bool is_letter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
  // TinyXML counts every byte from 127 up as a letter.
  static bool is_name_start(char c) { return is_letter(c) || c == '_' || static_cast<unsigned char>(c) >= 127; }
  static bool is_name_char(char c) {
    return is_name_start(c) || (c >= '0' && c <= '9') || c == '-' || c == '.' || c == ':';
  }
  static bool starts_with(const char* p, const char* s) { return std::strncmp(p, s, std::strlen(s)) == 0; }
  static char ascii_lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }
  static bool starts_with_nocase(const char* p, const char* s) {
    for (; *s; ++p, ++s)
      if (!*p || ascii_lower(*p) != ascii_lower(*s)) return false;
    return true;
  }
  static const char* skip_space(const char* p) {
    while (*p && is_space(*p)) ++p;
    return p;
  }
  // Past the next `end`, or null (the rest is swallowed: TinyXML stops or fails).
  static const char* skip_past(const char* p, const char* end) {
    const char* q = std::strstr(p, end);
    return q ? q + std::strlen(end) : nullptr;
  }
  static const char* name(const char* p) {
    if (!is_name_start(*p)) return nullptr;
    while (*p && is_name_char(*p)) ++p;
    return p;
  }

  // One character of text or of a quoted value, where TinyXML decodes references. A numeric one makes it
  // search for the next ';' and skip everything up to it; only a well-formed reference is let through.
  const char* character(const char* p) const {
    if (p[0] != '&' || p[1] != '#' || !p[2]) return p + 1;
    const bool hex = p[2] == 'x';
    const char* q = p + (hex ? 3 : 2);
    const char* digits = q;
    while (hex ? std::isxdigit(static_cast<unsigned char>(*q)) : (*q >= '0' && *q <= '9')) ++q;
    if (q == digits || *q != ';') fail(p, "a malformed character reference (expected &#digits; or &#xhex;)");
    return q + 1;
  }

  // An element's text up to the next '<' (TinyXML's Text::Parse); null where TinyXML fails.
  const char* text(const char* p) const {
    while (*p && *p != '<') p = character(p);
    return *p && p[1] ? p : nullptr;
  }

  // A quoted value after its opening quote, through the closing one (TinyXML's ReadText).
  const char* quoted(const char* p, char quote) const {
    while (*p && *p != quote) p = character(p);
    return *p && p[1] ? p + 1 : nullptr;
  }

  // name = "value" (TinyXML's Attribute::Parse); null where TinyXML fails.
  const char* attribute(const char* p) const {
    p = name(skip_space(p));
    if (!p) return nullptr;
    p = skip_space(p);
    if (*p != '=') return nullptr;
    p = skip_space(p + 1);
    if (*p == '"' || *p == '\'') return quoted(p + 1, *p);
    for (; *p && !is_space(*p) && *p != '/' && *p != '>'; ++p)  // an unquoted value
      if (*p == '"' || *p == '\'') return nullptr;
    return p;
  }

  // <name attributes> or <name attributes/> (TinyXML's Element::Parse up to the element's content).
  const char* start_tag(const char* p, bool& empty) const {
    p = name(p + 1);
    while (p && *p) {
      p = skip_space(p);
      if (*p == '/') {
        empty = true;
        return p[1] == '>' ? p + 2 : nullptr;
      }
      if (*p == '>') return p + 1;
      p = attribute(p);
    }
    return nullptr;
  }

  // </name > (a name other than the open element's makes TinyXML fail, and then nothing more is read).
  const char* end_tag(const char* p) const {
    p = name(p + 2);
    if (!p) return nullptr;
    p = skip_space(p);
    return *p == '>' ? p + 1 : nullptr;
  }

  // <?xml ... > from after "<?xml" (TinyXML's Declaration::Parse): version, encoding and standalone are read
  // as attributes (their quoted values may hold '>'), anything else up to white space or '>'.
  const char* declaration(const char* p) const {
    while (p && *p) {
      if (*p == '>') return p + 1;
      p = skip_space(p);
      if (starts_with_nocase(p, "version") || starts_with_nocase(p, "encoding") ||
          starts_with_nocase(p, "standalone")) {
        p = attribute(p);
      } else {
        while (*p && *p != '>' && !is_space(*p)) ++p;
      }
    }
    return nullptr;
  }

  const std::string& text_;
  const char* p_;
};

// ---------------------------------------------------------------------------------------------------------
// urdfdom's messages. console_bridge has one global output handler; while a thread parses, this handler
// keeps that thread's errors and passes other threads' messages on to the handler that was installed
// before (as that handler's level would have). One parse at a time (the mutex), so nothing nests.

class CapturingHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char* filename, int line) override {
    // console_bridge calls this under its own lock, the same lock that installs and removes the handler,
    // so the fields below, set before installing, are seen here.
    if (std::this_thread::get_id() == owner_) {
      if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors_.push_back(text);
      return;  // urdfdom's debug, info and warnings are not ours to print
    }
    if (forward_ && level >= forward_level_) forward_->log(text, level, filename, line);
  }

  std::vector<std::string> parse(const std::string& xml, urdf::ModelInterfaceSharedPtr& model) {
    owner_ = std::this_thread::get_id();
    errors_.clear();
    forward_ = console_bridge::getOutputHandler();
    forward_level_ = console_bridge::getLogLevel();
    console_bridge::useOutputHandler(this);
    const bool lowered = forward_level_ > console_bridge::CONSOLE_BRIDGE_LOG_ERROR;  // errors must reach us
    if (lowered) console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_ERROR);
    std::exception_ptr error;
    try {
      model = urdf::parseURDF(xml);
    } catch (...) {
      error = std::current_exception();
    }
    if (lowered) console_bridge::setLogLevel(forward_level_);
    if (console_bridge::getOutputHandler() == this) console_bridge::restorePreviousOutputHandler();
    owner_ = std::thread::id();
    if (error) std::rethrow_exception(error);
    return std::move(errors_);
  }

 private:
  std::thread::id owner_;
  std::vector<std::string> errors_;
  console_bridge::OutputHandler* forward_ = nullptr;
  console_bridge::LogLevel forward_level_ = console_bridge::CONSOLE_BRIDGE_LOG_WARN;
};

std::string joined(const std::vector<std::string>& messages) {
  std::string out;
  for (const auto& m : messages) {
    std::string line = m;
    while (!line.empty() && (line.back() == '\n' || line.back() == ' ')) line.pop_back();
    if (line.empty()) continue;
    if (!out.empty()) out += "; ";
    out += line;
  }
  return out;
}

}  // namespace

std::string read_urdf_file(const std::string& path) {
  if (path.find('\0') != std::string::npos)  // open() would read another file: the name up to the NUL
    throw InputError("the URDF path contains a NUL character");
  const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0)
    throw InputError("cannot read URDF file '" + path + "': " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0)
    throw InputError("cannot read URDF file '" + path + "': " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw InputError("the URDF path '" + path + "' is " + file_kind(st.st_mode) + ", not a file");
  if (static_cast<unsigned long long>(st.st_size) > limits::kMaxUrdfBytes)
    throw InputError("the URDF file '" + path + "' is " + std::to_string(st.st_size) + " bytes; at most " +
                     std::to_string(limits::kMaxUrdfBytes) + " are read");
  // Read at most one byte beyond the limit: a file that grows, or a /proc file whose size says 0, stays bounded.
  std::string text;
  char buf[65536];
  for (;;) {
    const ssize_t got = ::read(fd.get(), buf, sizeof buf);
    if (got < 0) {
      if (errno == EINTR) continue;
      throw InputError("cannot read URDF file '" + path + "': " + std::strerror(errno));
    }
    if (got == 0) break;
    text.append(buf, static_cast<std::size_t>(got));
    if (text.size() > limits::kMaxUrdfBytes)
      throw InputError("the URDF file '" + path + "' holds more than " + std::to_string(limits::kMaxUrdfBytes) +
                       " bytes; at most that many are read");
  }
  return text;
}

void check_urdf_document(const std::string& xml) { DocumentScan(xml).run(); }

urdf::ModelInterfaceSharedPtr parse_urdf(const std::string& xml) {
  check_urdf_document(xml);
  static std::mutex mutex;
  static auto* handler = new CapturingHandler;  // never destroyed: console_bridge may still point at it at exit
  std::vector<std::string> errors;
  urdf::ModelInterfaceSharedPtr model;
  {
    std::lock_guard<std::mutex> lock(mutex);
    try {
      errors = handler->parse(xml, model);
    } catch (const std::exception& e) {
      throw InputError(std::string("malformed URDF: ") + e.what());
    }
  }
  if (!model)
    throw InputError("malformed URDF: " + (errors.empty() ? std::string("urdfdom could not parse the document (not a "
                                                                        "valid <robot> description)")
                                                          : joined(errors)));
  if (!errors.empty())  // urdfdom left out what it could not read (e.g. a link's <inertial>) and carried on
    throw InputError("malformed URDF: " + joined(errors));
  return model;
}

}  // namespace snakehead
