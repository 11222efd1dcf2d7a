#include "Memory.h"

#include <vdbhair/Exceptions.h>

#include <cstdio>
#include <fstream>
#include <limits>


namespace vdbhair {

std::uint64_t availableMemoryBytes(std::uint64_t maxMemory)
{
    if (maxMemory > 0) return maxMemory;
    std::ifstream in("/proc/meminfo");
    std::string key, unit;
    std::uint64_t kib = 0;
    while (in >> key >> kib) {
        std::getline(in, unit);
        if (key == "MemAvailable:") return kib * 1024;
    }
    return std::numeric_limits<std::uint64_t>::max();
}

std::string formatBytes(std::uint64_t bytes)
{
    char buf[64];
    if (bytes >= (std::uint64_t(1) << 30)) std::snprintf(buf, sizeof buf, "%.2f GiB", double(bytes) / double(1 << 30));
    else if (bytes >= (std::uint64_t(1) << 20)) std::snprintf(buf, sizeof buf, "%.0f MiB", double(bytes) / double(1 << 20));
    else if (bytes >= 1024) std::snprintf(buf, sizeof buf, "%.0f KiB", double(bytes) / 1024.0);
    else std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
    return buf;
}

void checkMemory(const std::string& where, std::uint64_t estimate, const std::string& how, const std::string& advice, std::uint64_t maxMemory)
{
    checkMemory(where, estimate, how, ParamText{advice}, maxMemory, ParamName{"maxMemory", "maxMemory"});
}

void checkMemory(const std::string& where, std::uint64_t estimate, const std::string& how, const ParamText& advice,
                 std::uint64_t maxMemory, const ParamName& maxMemoryName)
{
    const std::uint64_t available = availableMemoryBytes(maxMemory);
    if (estimate <= available) return;
    ParamText text{where + ": needs about " + formatBytes(estimate) + " (" + how + "), more than the " + formatBytes(available)};
    if (maxMemory > 0) text += " of ", text += maxMemoryName;
    else text += " available (MemAvailable)";
    const std::string plain = advice.spelled(ParamSpelling::Keyword);
    if (!plain.empty()) text += "; ", text += advice;
    throw ParamError<LimitError>(text);
}

namespace {
thread_local AllocationBudget* tBudget = nullptr;
}

BudgetExceeded::BudgetExceeded(std::uint64_t requested, std::uint64_t live, std::uint64_t limit)
    : mRequested(requested), mLive(live), mLimit(limit)
{
    std::snprintf(mWhat, sizeof mWhat, "allocation of %llu bytes with %llu live would pass the budget of %llu bytes",
                  static_cast<unsigned long long>(requested), static_cast<unsigned long long>(live),
                  static_cast<unsigned long long>(limit));
}

AllocationBudget::AllocationBudget(std::uint64_t limit) : mLimit(limit), mOuter(tBudget)
{
    if (mOuter) mLimit = std::min(mLimit, mOuter->mLimit - std::min(mOuter->mLimit, mOuter->mLive));
    tBudget = this;
}

AllocationBudget::~AllocationBudget()
{
    tBudget = mOuter;
    if (mOuter) {
        mOuter->mPeak = std::max(mOuter->mPeak, mOuter->mLive + mPeak);
        mOuter->mLive += mLive;
    }
}

AllocationBudget* AllocationBudget::current() { return tBudget; }

void AllocationBudget::charge(std::size_t request)
{
    if (request > mLimit || mLive > mLimit - request) throw BudgetExceeded(request, mLive, mLimit);
}

std::uint64_t readBudgetBytes(std::uint64_t fileBytes, std::uint64_t maxMemory)
{
    const std::uint64_t cap = std::numeric_limits<std::uint64_t>::max();
    const std::uint64_t rule = fileBytes > (cap - kReadBudgetFloor) / kReadBudgetPerFileByte ? cap
                                                                                             : kReadBudgetFloor + kReadBudgetPerFileByte * fileBytes;
    return std::min(rule, availableMemoryBytes(maxMemory));
}

} // namespace vdbhair
