#pragma once
// The GenICam description of a GenTL port, found by the port's URL (GenTL "Port URL"):
//   local:[///]name.xml;ADDRESS;LENGTH[?SchemaVersion=...]   in the port's own register space
//   local:[///]name.zip;ADDRESS;LENGTH                        the same, zipped
//   file:///path/name.xml (or .zip)                           a file on the host
// ADDRESS and LENGTH are hexadecimal. Trailing NULs (a register block padded to its length)
// are removed. http: URLs (a vendor's web site) are refused with a message.
#include <string>

#include "gentl_producer.h"

namespace tomorig::acquisition::gentl_detail {

// Throws runtime_error naming `what` (e.g. "camera cam0") and the URL when the description
// cannot be read or unpacked.
std::string fetch_port_xml(Producer& producer, gentl::Handle port, const std::string& what);

// The URL's parts (exposed for tests).
struct PortUrl {
  enum class Scheme { local, file, other } scheme = Scheme::other;
  std::string file_name;     // local: the name; file: the path
  std::uint64_t address = 0;  // local only
  std::uint64_t length = 0;   // local only
  bool zipped = false;
};
// Throws runtime_error naming the URL when it is malformed.
PortUrl parse_port_url(const std::string& url);

}  // namespace tomorig::acquisition::gentl_detail
