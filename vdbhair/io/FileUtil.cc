#include "FileUtil.h"
#include "MappedFile.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parameters.h>
#include <vdbhair/Progress.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace vdbhair {

namespace fs = std::filesystem;

void requireRegularFile(const std::string& path, const std::string& where)
{
    struct stat st;
    if (::stat(path.c_str(), &st) != 0) throw IoError(where + ": cannot open for reading: " + std::strerror(errno));
    if (S_ISREG(st.st_mode)) return;
    const char* what = S_ISDIR(st.st_mode)    ? "a directory"
                       : S_ISFIFO(st.st_mode) ? "a FIFO (named pipe)"
                       : S_ISSOCK(st.st_mode) ? "a socket"
                       : S_ISCHR(st.st_mode)  ? "a character device"
                       : S_ISBLK(st.st_mode)  ? "a block device"
                                              : "not a regular file";
    throw IoError(where + ": is " + std::string(what) + ", not a regular file; inputs must be regular files");
}

std::vector<char> readFileBytes(const std::string& path, const std::string& where, openvdb::util::NullInterrupter* interrupter)
{
    requireRegularFile(path, where);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw IoError(where + ": cannot open for reading: " + std::strerror(errno));
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) throw IoError(where + ": cannot determine the file size");
    in.seekg(0, std::ios::beg);
    std::vector<char> bytes(static_cast<std::size_t>(size));
    // In pieces, so that a big file's progress shows and Ctrl-C is heard.
    constexpr std::streamoff kPiece = std::streamoff(8) << 20;
    const std::string stage = "reading " + fs::path(path).filename().string();
    ProgressCounter progress(interrupter, stage.c_str(), std::uint64_t(size), "bytes");
    for (std::streamoff done = 0; done < size;) {
        const std::streamoff n = std::min(kPiece, size - done);
        if (!in.read(bytes.data() + done, n)) {
            throw IoError(where + ": read failed after " + std::to_string(done + in.gcount()) + " of " +
                          std::to_string(size) + " bytes");
        }
        done += n;
        if (progress.add(std::uint64_t(n))) throw InterruptedError(where + ": interrupted while reading");
    }
    return bytes;
}

MappedFile::MappedFile(const std::string& path, const std::string& where, openvdb::util::NullInterrupter* interrupter)
{
    requireRegularFile(path, where);
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw IoError(where + ": cannot open for reading: " + std::strerror(errno));
    struct stat st;
    if (::fstat(fd, &st) != 0 || st.st_size < 0) {
        const std::string reason = std::strerror(errno);
        ::close(fd);
        throw IoError(where + ": cannot determine the file size: " + reason);
    }
    mSize = std::size_t(st.st_size);
    const std::string stage = "reading " + fs::path(path).filename().string();
    ProgressCounter progress(interrupter, stage.c_str(), std::uint64_t(mSize), "bytes");
    if (mSize > 0) {
        // MAP_POPULATE maps every page of the page cache in one call (no fault per page).
        void* m = ::mmap(nullptr, mSize, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
        if (m != MAP_FAILED) {
            mMap = m;
            mData = static_cast<const char*>(m);
        }
    }
    ::close(fd);
    if (!mMap) {
        // Not mappable (or empty): read it the ordinary way.
        mBuffer = readFileBytes(path, where);
        mSize = mBuffer.size();
        mData = mBuffer.data();
    }
    if (progress.add(std::uint64_t(mSize))) {
        if (mMap) ::munmap(mMap, mSize);  // the destructor does not run for a throwing constructor
        throw InterruptedError(where + ": interrupted while reading");
    }
}

MappedFile::~MappedFile()
{
    if (mMap) ::munmap(mMap, mSize);
}

std::string fileExtension(const std::string& path)
{
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

AtomicOutput::AtomicOutput(std::string target) : mTarget(std::move(target))
{
    static std::atomic<unsigned> counter{0};
    const fs::path p(mTarget);
    fs::path dir = p.parent_path();
    std::error_code ec;
    if (!dir.empty() && !fs::is_directory(dir, ec)) {
        throw IoError(mTarget + ": cannot write: folder '" + dir.string() + "' does not exist");
    }
    if (fs::is_directory(p, ec)) throw IoError(mTarget + ": cannot write: is a directory");
    const std::string name = "." + p.stem().string() + ".vdbhair-tmp-" +
                             std::to_string(::getpid()) + "-" + std::to_string(counter++) +
                             p.extension().string();
    mTemp = (dir.empty() ? fs::path(name) : dir / name).string();
}

AtomicOutput::~AtomicOutput()
{
    if (!mCommitted) {
        std::error_code ec;
        fs::remove(mTemp, ec);
    }
}

namespace {
std::atomic<bool (*)()> sCommitInterrupt{nullptr};
}

void setCommitInterruptCheck(bool (*check)()) { sCommitInterrupt.store(check); }

namespace {
std::atomic<OverwritePolicy> sOverwrite{OverwritePolicy::Replace};
}

void setOverwritePolicy(OverwritePolicy policy) { sOverwrite.store(policy); }
OverwritePolicy overwritePolicy() { return sOverwrite.load(); }

void AtomicOutput::commit()
{
    if (bool (*check)() = sCommitInterrupt.load(); check && check()) {
        std::error_code ec;
        fs::remove(mTemp, ec);
        throw InterruptedError(mTarget + ": interrupted before the output was moved into place");
    }
    if (sOverwrite.load() == OverwritePolicy::NoClobber) {
        // link() never replaces: it fails with EEXIST when the target exists, atomically.
        if (::link(mTemp.c_str(), mTarget.c_str()) != 0) {
            const int err = errno;
            std::error_code ec;
            fs::remove(mTemp, ec);
            // The policy is the command line's --no-clobber; Python always replaces.
            if (err == EEXIST) {
                throw ParamError<IoError>({mTarget + ": exists; ", ParamName{"--no-clobber", "OverwritePolicy::NoClobber"},
                                           " refuses to replace it (nothing was written)"});
            }
            throw IoError(mTarget + ": cannot move the finished output into place: " + std::strerror(err));
        }
        std::error_code ec;
        fs::remove(mTemp, ec);
        mCommitted = true;
        return;
    }
    if (std::rename(mTemp.c_str(), mTarget.c_str()) != 0) {
        const std::string reason = std::strerror(errno);
        std::error_code ec;
        fs::remove(mTemp, ec);
        throw IoError(mTarget + ": cannot move the finished output into place: " + reason);
    }
    mCommitted = true;
}

namespace {
constexpr std::size_t kWriteBuffer = std::size_t(1) << 20;
}

AtomicFileWriter::AtomicFileWriter(const std::string& path, std::string where) : mOut(path), mWhere(std::move(where))
{
    mFd = ::open(mOut.tempPath().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (mFd < 0) throw IoError(mWhere + ": cannot open '" + mOut.tempPath() + "' for writing: " + std::strerror(errno));
}

AtomicFileWriter::~AtomicFileWriter()
{
    if (mFd >= 0) ::close(mFd);  // not committed: AtomicOutput's destructor removes the temporary
}

void AtomicFileWriter::writeAll(const char* data, std::size_t n)
{
    while (n > 0) {
        const ssize_t w = ::write(mFd, data, std::min<std::size_t>(n, std::size_t(1) << 30));
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) throw IoError(mWhere + ": write failed (disk full?): " + std::strerror(w < 0 ? errno : ENOSPC));
        data += w;
        n -= std::size_t(w);
    }
}

void AtomicFileWriter::flush()
{
    writeAll(mBuffer.data(), mUsed);
    mUsed = 0;
}

void AtomicFileWriter::append(const void* data, std::size_t n)
{
    const char* p = static_cast<const char*>(data);
    if (n >= kWriteBuffer) {
        flush();
        writeAll(p, n);
        return;
    }
    if (mBuffer.empty()) mBuffer.resize(kWriteBuffer);
    if (mUsed + n > kWriteBuffer) flush();
    std::memcpy(mBuffer.data() + mUsed, p, n);
    mUsed += n;
}

void AtomicFileWriter::commit()
{
    flush();
    const int fd = mFd;
    mFd = -1;
    if (::close(fd) != 0) throw IoError(mWhere + ": write failed (disk full?): " + std::strerror(errno));
    mOut.commit();
}

void writeFileAtomic(const std::string& path, const std::string& bytes, const std::string& where)
{
    AtomicFileWriter out(path, where);
    out.append(bytes.data(), bytes.size());
    out.commit();
}

} // namespace vdbhair
