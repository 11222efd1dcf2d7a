/// @file FileUtil.h
/// @brief Reading whole files and writing outputs safely (temporary file, then rename).
#pragma once

#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief Fail unless @a path names an existing regular file (or a symbolic link to one), before
/// anything opens it: a directory, a FIFO (whose open would block), a socket or a device says so.
/// @param where prefix of error messages
/// @throw IoError naming what @a path is instead.
void requireRegularFile(const std::string& path, const std::string& where);

/// @brief The whole content of @a path.
/// @param where prefix of error messages, e.g. "readHair(a.hair)"
/// @param interrupter optional progress (bytes read) and Ctrl-C (Progress.h)
/// @throw IoError if the file cannot be opened or read; InterruptedError when the interrupter
/// stops the reading.
std::vector<char> readFileBytes(const std::string& path, const std::string& where,
                                openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief Lower-case extension of @a path including the dot (".hair"), or "" if none.
std::string fileExtension(const std::string& path);

/// @brief An output written to a temporary file next to its target and renamed into place by
/// commit(), so that a failed run never leaves a half-written file nor destroys an existing one.
///
/// The temporary keeps the target's extension (some writers, such as OpenImageIO, choose the
/// format by it). If commit() is not called, the destructor removes the temporary.
class AtomicOutput
{
public:
    /// @throw IoError if the target's folder does not exist.
    explicit AtomicOutput(std::string target);
    ~AtomicOutput();
    AtomicOutput(const AtomicOutput&) = delete;
    AtomicOutput& operator=(const AtomicOutput&) = delete;

    const std::string& target() const { return mTarget; }
    /// Where to write: a path in the target's folder.
    const std::string& tempPath() const { return mTemp; }
    /// @brief Rename the temporary onto the target (under OverwritePolicy::NoClobber: link it to
    /// the target, which fails atomically if the target exists).
    /// @throw IoError with the operating system's reason or, with NoClobber, because the target
    /// exists; InterruptedError (and the temporary
    /// removed) when the check of setCommitInterruptCheck() says so.
    void commit();

private:
    std::string mTarget, mTemp;
    bool mCommitted = false;
};

/// @brief Install a process-wide check that AtomicOutput::commit() runs before renaming: when it
/// returns true, the temporary is removed and commit() throws InterruptedError. Commands set it to
/// their Ctrl-C flag, so that work interrupted anywhere, even while writing, leaves no output.
/// nullptr (the default) removes it.
void setCommitInterruptCheck(bool (*check)());

/// What AtomicOutput::commit() does when the target already exists.
enum class OverwritePolicy
{
    Replace,   ///< rename over it atomically (the default)
    NoClobber, ///< refuse: commit() throws IoError and the existing file is left as it was
};

/// @brief Set the process-wide OverwritePolicy (the command's `--no-clobber`). Thread-safe.
void setOverwritePolicy(OverwritePolicy policy);
OverwritePolicy overwritePolicy();

/// @brief An output file written as a stream of pieces into an AtomicOutput's temporary and
/// renamed into place by commit(). Small pieces gather in a buffer of 1 MiB; a piece as large as
/// the buffer goes to write(2) straight from the caller's memory. So a writer need not assemble
/// the whole file first: a 77 MB strand file then costs no fresh memory (whose pages the kernel
/// must clear) and one copy fewer.
class AtomicFileWriter
{
public:
    /// @throw IoError if the temporary cannot be created (see AtomicOutput).
    AtomicFileWriter(const std::string& path, std::string where);
    ~AtomicFileWriter();
    AtomicFileWriter(const AtomicFileWriter&) = delete;
    AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

    /// @throw IoError when a write fails (disk full, ...).
    void append(const void* data, std::size_t n);
    template<typename T>
    void appendValue(const T& v) { append(&v, sizeof(T)); }
    /// Flush, close and rename onto the target (AtomicOutput::commit()).
    void commit();

private:
    void flush();
    void writeAll(const char* data, std::size_t n);

    AtomicOutput mOut;
    std::string mWhere;
    int mFd = -1;
    std::vector<char> mBuffer;
    std::size_t mUsed = 0;
};

/// @brief Write @a bytes to @a path atomically (see AtomicOutput).
void writeFileAtomic(const std::string& path, const std::string& bytes, const std::string& where);

} // namespace vdbhair
