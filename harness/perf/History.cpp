#include "harness/perf/History.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <random>

#include "core/base/ShownText.h"
#include "harness/platform/OutputFolder.h"
#include "harness/platform/PosixIo.h"

namespace cb::perf {

std::string DefaultHistoryPath() {
    if (const char* path = std::getenv("CLOUDBENCH_HISTORY"); path && *path) return path;
    if (const char* data = std::getenv("XDG_DATA_HOME"); data && *data)
        return std::string(data) + "/cloudbench/history.jsonl";
    const char* home = std::getenv("HOME");
    return std::string(home && *home ? home : ".") + "/.local/share/cloudbench/history.jsonl";
}

Result<std::vector<HistoryRecord>> ReadHistory(const std::string& path) {
    Result<input::History> history = input::ReadHistory(path);
    if (!history) return std::unexpected(history.error());
    input::PrintWarnings(*history);
    return std::move(history->records);
}

Status AppendRecord(const std::string& path, const nlohmann::json& record) {
    // Like every file the user names (core/base/PathPolicy.h): its folder is followed, a link at its own name is
    // refused, never appended through, and a FIFO or a device is refused without blocking.
    Result<int> opened = OpenAppendFile(path);
    if (!opened) return std::unexpected(opened.error());
    const int fd = *opened;
    auto fail = [&] {
        const int error = errno;
        ::close(fd);
        return MakeError(path + ": cannot write: " + std::strerror(error));
    };
    std::string line = record.dump() + "\n";
    // A previous line cut short has no newline: end it, so this record stays readable.
    struct stat st {};
    if (::fstat(fd, &st) == 0 && st.st_size > 0) {
        char last = '\n';
        if (::pread(fd, &last, 1, st.st_size - 1) != 1) last = '\n';
        if (last != '\n') line.insert(line.begin(), '\n');
    }
    if (!WriteAll(fd, line) || ::fsync(fd) != 0) return fail();
    if (::close(fd) != 0) return MakeError(path + ": cannot write: " + std::strerror(errno));
    return {};
}

Result<const HistoryRecord*> SelectRecord(const std::vector<HistoryRecord>& records, const std::string& path,
                                          const std::string& selector) {
    const std::string name = path + "@" + ShownText(selector);
    if (selector.empty()) return MakeError(name + ": no record named after '@' (give an id, a unique prefix of one, or -N)");
    if (records.empty()) return MakeError(name + ": the history holds no record");
    if (selector.size() > 1 && selector[0] == '-' && selector.find_first_not_of("0123456789", 1) == std::string::npos) {
        const size_t back = std::strtoul(selector.c_str() + 1, nullptr, 10);
        if (back == 0 || back > records.size())
            return MakeError(name + ": the history holds " + std::to_string(records.size()) + " records");
        return &records[records.size() - back];
    }
    const HistoryRecord* match = nullptr;
    for (const HistoryRecord& r : records) {
        const std::string id = r.record.value("id", "");
        if (id == selector) return &r;
        if (!selector.empty() && id.starts_with(selector)) {
            if (match) return MakeError(name + ": more than one record id starts with '" + selector + "'");
            match = &r;
        }
    }
    if (!match) return MakeError(name + ": no record with this id");
    return match;
}

Result<std::vector<const HistoryRecord*>> SelectRecords(const std::vector<HistoryRecord>& records,
                                                        const std::string& path, const std::string& selector) {
    const size_t colon = selector.find(':');
    if (colon == std::string::npos) {
        auto one = SelectRecord(records, path, selector);
        if (!one) return std::unexpected(one.error());
        return std::vector<const HistoryRecord*>{*one};
    }
    if (records.empty()) return MakeError(path + "@" + ShownText(selector) + ": the history holds no record");
    const std::string from = selector.substr(0, colon), to = selector.substr(colon + 1);
    const HistoryRecord* first = &records.front();
    const HistoryRecord* last = &records.back();
    if (!from.empty()) {
        auto r = SelectRecord(records, path, from);
        if (!r) return std::unexpected(r.error());
        first = *r;
    }
    if (!to.empty()) {
        auto r = SelectRecord(records, path, to);
        if (!r) return std::unexpected(r.error());
        last = *r;
    }
    if (first > last)
        return MakeError(path + "@" + ShownText(selector) + ": the range starts at line " +
                         std::to_string(first->line) + ", after its end at line " + std::to_string(last->line) +
                         " (write the earlier record first: FILE@-8:-5)");
    std::vector<const HistoryRecord*> chosen;
    for (const HistoryRecord* r = first; r <= last; ++r) chosen.push_back(r);
    return chosen;
}

std::string NewRecordId() {
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char text[40];
    std::strftime(text, sizeof text, "%Y%m%dT%H%M%SZ", &utc);
    std::random_device random;
    char suffix[16];
    std::snprintf(suffix, sizeof suffix, "-%06x", unsigned(random() & 0xffffffu));
    return text + std::string(suffix);
}

}  // namespace cb::perf
