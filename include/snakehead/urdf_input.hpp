// Robot descriptions on their way to urdfdom: read, checked, parsed, with urdfdom's messages kept.
//
// urdfdom 3.0 (Debian's) parses with TinyXML 2.6, which recurses once per element nesting level with no
// limit: a document nested 40,000 deep (280 kB) overflows the stack. urdfdom reports problems through
// console_bridge, which prints them, and drops an <inertial> or <collision> it cannot parse without failing.
// So every description is
//  - read from a regular file only, at most limits::kMaxUrdfBytes (not /dev/zero, a FIFO or a directory);
//  - scanned, without recursion, for its size, NUL bytes, UTF-8 and its element nesting depth (at most
//    limits::kMaxUrdfDepth), following TinyXML's own reading of the text so that the depth counted is the
//    depth TinyXML would reach;
//  - parsed with console_bridge's output captured for the calling thread: nothing is printed, and any error
//    urdfdom reports (also one it then ignores) becomes the InputError's message.
#pragma once

#include <urdf_model/model.h>
#include <urdf_world/types.h>

#include <string>

namespace snakehead {

// The text of the URDF file at `path`. Throws InputError when it is not a readable regular file or is
// larger than limits::kMaxUrdfBytes.
std::string read_urdf_file(const std::string& path);

// Throws InputError (with the line) when `xml` is larger than limits::kMaxUrdfBytes, holds a NUL byte,
// is not UTF-8, holds a malformed numeric character reference (&#...;), or nests elements deeper than
// limits::kMaxUrdfDepth levels.
void check_urdf_document(const std::string& xml);

// check_urdf_document, then urdfdom's parser. Throws InputError with urdfdom's own messages when it
// rejects the document or reports an error while accepting it (e.g. an <inertial> it could not read and
// left out). Safe to call from many threads at once.
urdf::ModelInterfaceSharedPtr parse_urdf(const std::string& xml);

}  // namespace snakehead
