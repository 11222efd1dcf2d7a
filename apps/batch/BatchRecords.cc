#include "BatchRecords.h"

#include <vdbhair/Exceptions.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace vdbhair::app {

namespace {

/// Write all of @a bytes to @a fd (one write() for a record line; the loop only continues a short write).
void writeAll(int fd, const std::string& bytes, const std::string& path)
{
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw IoError(path + ": cannot append a record: " + std::strerror(errno));
        done += std::size_t(n);
    }
}

} // namespace

RecordFile readRecords(const std::string& path)
{
    RecordFile out;
    std::ifstream f(path, std::ios::binary);
    if (!f) {
        if (errno == ENOENT) return out;
        throw IoError(path + ": cannot read the batch records: " + std::strerror(errno));
    }
    std::string line;
    while (std::getline(f, line)) {
        if (line.empty()) continue;
        nlohmann::json j = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
        if (j.is_object() && j.contains("input") && j["input"].is_string() && j.contains("job") && j["job"].is_string() &&
            j.contains("status") && j["status"].is_string()) {
            out.records.push_back(std::move(j));
        } else {
            ++out.skippedLines;
        }
    }
    return out;
}

std::map<std::pair<std::string, std::string>, nlohmann::json> latestRecords(const std::vector<nlohmann::json>& records)
{
    std::map<std::pair<std::string, std::string>, nlohmann::json> latest;
    for (const nlohmann::json& r : records) latest[{r["input"].get<std::string>(), r["job"].get<std::string>()}] = r;
    return latest;
}

RecordAppender::RecordAppender(std::string path) : mPath(std::move(path))
{
    mFd = ::open(mPath.c_str(), O_RDWR | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (mFd < 0) throw IoError(mPath + ": cannot open the batch records for appending: " + std::strerror(errno));
    struct stat st{};
    char last = '\n';
    if (::fstat(mFd, &st) == 0 && st.st_size > 0 && ::pread(mFd, &last, 1, st.st_size - 1) == 1 && last != '\n') {
        writeAll(mFd, "\n", mPath);  // a killed writer's truncated line stays a line of its own
    }
}

RecordAppender::~RecordAppender()
{
    if (mFd >= 0) ::close(mFd);
}

void RecordAppender::append(const nlohmann::json& record)
{
    // A child's stderr may hold any bytes: invalid UTF-8 becomes U+FFFD rather than an exception.
    writeAll(mFd, record.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n", mPath);
    if (::fsync(mFd) != 0) throw IoError(mPath + ": cannot sync the batch records: " + std::strerror(errno));
}

} // namespace vdbhair::app
