#pragma once
// Result files appear whole or not at all: a run that fails half way (a full disk, a crashed
// plotting program, an exception in a writer) must not leave a truncated fields.h5 or surface.vtu
// that a later `msfem regress` or a ParaView session would take for a result.

#include <filesystem>
#include <functional>
#include <string>

namespace msfem::compare {

/// Calls `write` with a temporary name in the same folder as `path` (`<name>.tmp.<pid>`, so the
/// final rename stays on one file system and is atomic), then renames the temporary onto `path`,
/// replacing any file there. If `write` throws or leaves no file, the temporary is removed, `path`
/// is left as it was, and a std::runtime_error naming `path` is thrown (with the cause's message).
void write_file_atomically(
    const std::filesystem::path& path,
    const std::function<void(const std::filesystem::path& temporary)>& write);

/// write_file_atomically for a text: the whole of `text`, flushed and checked before the rename.
void write_text_atomically(const std::filesystem::path& path, const std::string& text);

/// Throws cases::InputError if `directory` is empty or exists and is not empty (what
/// fill_directory_atomically refuses before it starts).
void check_output_folder(const std::filesystem::path& directory);

/// Creates `directory` with everything `fill` writes into the temporary folder it is given, renamed
/// into place only when `fill` returns: a failed run leaves no folder behind. Throws
/// cases::InputError, before `fill` runs, if `directory` is empty, exists and is not empty, or its
/// temporary cannot be created there; rethrows whatever `fill` throws.
void fill_directory_atomically(const std::filesystem::path& directory,
                               const std::function<void(const std::filesystem::path& work)>& fill);

/// The FEM cache of a command whose results go to `run_folder`: `.fem-cache` in the folder that
/// holds it (so `--out DIR` keeps its cache beside DIR, not in the working directory). Created now:
/// a place that cannot be written is a cases::InputError before any solve.
std::filesystem::path fem_cache_beside(const std::filesystem::path& run_folder);

}  // namespace msfem::compare
