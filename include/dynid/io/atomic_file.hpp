#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace dynid {

/// Writes a file atomically (docs/design.md section 4): `write(out)` fills a temporary file
/// `<path>.tmp.<pid>` in the same directory, which is then flushed and renamed onto `path`. If
/// `write` throws, or the stream fails, the temporary file is removed and `path` is untouched (an
/// existing file keeps its old content); the exception propagates.
/// Throws dynid::Error when the directory does not exist or is not writable, or writing fails.
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& write);

/// write_file_atomic with a ready string.
void write_text_atomic(const std::string& path, const std::string& text);

}  // namespace dynid
