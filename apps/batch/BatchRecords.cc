#include "BatchRecords.h"

#include <vdbhair/Exceptions.h>

#include <algorithm>
#include <cerrno>
#include <functional>
#include <map>
#include <cstring>
#include <fstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace vdbhair::app {

namespace {

/// A report's cells by dotted path, in order met (a scalar, or an array of scalars joined by spaces).
void flatten(const nlohmann::json& j, const std::string& prefix, std::vector<std::pair<std::string, std::string>>& out)
{
    auto scalar = [](const nlohmann::json& v) -> std::string {
        if (v.is_string()) return v.get<std::string>();
        if (v.is_null()) return "";
        return v.dump();
    };
    if (j.is_object()) {
        for (auto it = j.begin(); it != j.end(); ++it) flatten(it.value(), prefix.empty() ? it.key() : prefix + "." + it.key(), out);
    } else if (j.is_array()) {
        std::string cell;
        bool flat = true;
        std::function<void(const nlohmann::json&)> add = [&](const nlohmann::json& v) {
            if (v.is_array()) {
                for (const auto& e : v) add(e);
            } else if (v.is_object()) {
                flat = false;
            } else {
                cell += (cell.empty() ? "" : " ") + scalar(v);
            }
        };
        add(j);
        if (flat) out.emplace_back(prefix, cell);
    } else {
        out.emplace_back(prefix, scalar(j));
    }
}

std::string csvCell(const std::string& s)
{
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

} // namespace

std::string manifestCsv(const std::vector<nlohmann::json>& records)
{
    std::vector<const nlohmann::json*> rows;
    for (const nlohmann::json& r : records) rows.push_back(&r);
    auto index = [](const nlohmann::json& r) { return r.contains("index") && r["index"].is_number() ? r["index"].get<long long>() : -1; };
    std::stable_sort(rows.begin(), rows.end(), [&](const nlohmann::json* a, const nlohmann::json* b) {
        if (index(*a) != index(*b)) return index(*a) < index(*b);
        return a->value("input", std::string()) < b->value("input", std::string());
    });
    std::vector<std::string> columns{"index", "input", "output", "status", "seconds", "error"};
    std::vector<std::map<std::string, std::string>> cells;
    for (const nlohmann::json* r : rows) {
        std::map<std::string, std::string> row;
        for (const char* c : {"index", "input", "output", "status", "seconds", "error"}) {
            if (r->contains(c)) {
                std::vector<std::pair<std::string, std::string>> v;
                flatten((*r)[c], c, v);
                if (!v.empty()) row[c] = v.front().second;
            }
        }
        if (r->contains("report") && (*r)["report"].is_object()) {
            std::vector<std::pair<std::string, std::string>> v;
            flatten((*r)["report"], "", v);
            for (const auto& [name, value] : v) {
                const std::string col = "report." + name;
                if (std::find(columns.begin(), columns.end(), col) == columns.end()) columns.push_back(col);
                row[col] = value;
            }
        }
        cells.push_back(std::move(row));
    }
    std::string text;
    for (std::size_t c = 0; c < columns.size(); ++c) text += (c ? "," : "") + csvCell(columns[c]);
    text += "\n";
    for (const auto& row : cells) {
        for (std::size_t c = 0; c < columns.size(); ++c) {
            const auto it = row.find(columns[c]);
            text += (c ? "," : "") + (it == row.end() ? std::string() : csvCell(it->second));
        }
        text += "\n";
    }
    return text;
}

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
