#pragma once

#include <cstddef>
#include <string>

namespace dynid {

/// The whole of the regular file `path`, at most `cap` bytes (what is read counts, not what stat
/// says). Opened without blocking, so a FIFO planted at the name is refused instead of waited on;
/// a symbolic link is followed unless `no_follow`. Throws dynid::Error "WHAT 'PATH': ...; FIX"
/// when the file cannot be opened or read, is not a regular file (a folder, device, FIFO or
/// socket) or is larger than `cap`.
std::string read_regular_file(const std::string& path, std::size_t cap, const std::string& what,
                              bool no_follow = false);

/// Throws dynid::Error "WHAT 'PATH' is not a regular file ..." when `path` exists and is a
/// folder, device, FIFO or socket, for readers that open the file themselves (a library's own
/// loader): opening a FIFO to read blocks until some other program writes to it, and a device
/// like /dev/zero never ends. No throw when `path` does not exist (the reader names that).
void require_regular_file(const std::string& path, const std::string& what);

}  // namespace dynid
