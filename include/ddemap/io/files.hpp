#pragma once
/// \file files.hpp
/// Files in and out at the edges: input text read whole (a folder is refused, a UTF-8
/// byte-order mark and CRLF line ends are accepted), output paths checked before any work, and
/// output sets written so that they are all new or all old.

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace ddemap {

/// A file could not be written (the message names the path and the system's reason).
struct WriteError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// `text` with a leading UTF-8 byte-order mark removed and every CRLF line end made LF; the
/// form every reader (CSV, JSON, TOML) expects.
std::string normalize_input_text(std::string text);

/// The whole file `path` as normalized text (normalize_input_text). std::invalid_argument
/// "'PATH' is a folder, expected a file" or "'PATH': cannot open the file (REASON)"; a file
/// that is not UTF-8 (e.g. a Latin-1 name) is refused naming its first bad byte:
/// "PATH:LINE: byte K (0xNN) is not UTF-8: expected UTF-8 text". At most 1 GB is read (a
/// larger file, or an endless stream such as /dev/zero, is refused).
std::string read_text_file(const std::string& path);

/// The file that writing `path` changes: `path` with every symbolic link followed (a link to a
/// missing file gives the missing file); `path` itself when it is not a link.
std::string resolve_output_path(const std::string& path);

/// Checks, before any work, that `path` can be written: throws std::invalid_argument naming
/// the path when it (after links) is a folder, when a part of its folder is a regular file,
/// when its folder is missing, or when the folder (or the special file) is not writable.
void check_output_file(const std::string& path);

/// Completes the output sets that writers killed during their final moves (SIGKILL, power
/// loss) left in `folder`: such a writer leaves a journal ".ddemap-set-PID-N.journal" naming each
/// new file by device and inode, and every file still old gets its new content from the hidden
/// file holding it (the set is then all new); the journal is removed, and so are the hidden
/// temporary files of writers no longer running (".NAME.ddemap-PID-N.tmp"). Called by every
/// read_text_file (in the file's folder) and write_files_atomic (in each output folder), so that
/// ddemap never reads or extends a half-moved set. Errors are ignored (the next call retries).
void complete_interrupted_output_sets(const std::string& folder);

/// Writes `text` to `path` as a set of one file (write_files_atomic).
void write_file_atomic(const std::string& path, const std::string& text);

/// Writes several files so that they are all new or all old:
/// - each regular file is written into an unnamed temporary file (O_TMPFILE) in its folder, or
///   into a hidden uniquely named one that an interrupt (SIGINT, SIGTERM, SIGHUP) removes, and
///   fsynced; nothing named is left behind by an interrupt while the files are written;
/// - then, with these signals held back, every file is moved into place (an existing file is
///   exchanged with the new one, so that a failed move puts every old file back) and the
///   folders are fsynced;
/// - a symbolic link is written through (its target is replaced, the link stays);
/// - a special file (a device such as /dev/null, a FIFO) is never replaced: the text is written
///   into it directly, before any regular file is moved.
/// - `remove`: files of an earlier run that are not part of this set (e.g. PREFIX-boundaries.csv
///   of a sweep now run without boundaries): removed together with the move, so that a folder
///   never holds old and new files of one command side by side (only regular files).
/// - a file this process has read (read_text_file) is never written over: std::invalid_argument
///   naming it, before anything is written (`classify mycars.csv --out mycars`).
/// - a set of two or more regular files: before the first move a journal is written in each of
///   its folders (complete_interrupted_output_sets), removed after the last; a SIGKILL during the
///   moves leaves it, and the next ddemap run reading from or writing into the folder completes
///   the set. So the set is all old (killed before the journal) or, once a later run has looked
///   at the folder, all new.
/// On a failure the old files stay as they were and no temporary file is left; WriteError
/// names the path and the system's reason (e.g. "No space left on device").
void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files, const std::vector<std::string>& remove = {});

}  // namespace ddemap
