#include "JsonFile.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>

namespace vdbhair {

namespace {

/// @brief A first, non-building pass over a document with nlohmann's SAX parser (itself
/// iterative): it knows the key path of every value, so that nesting deeper than the cap and
/// numbers beyond a double (1e400) are reported by path before any recursive code (building,
/// copying or destroying a json value) sees the document.
class JsonTextCheck : public nlohmann::json_sax<nlohmann::json>
{
public:
    JsonTextCheck(std::string where, std::size_t maxDepth, std::string noun)
        : mWhere(std::move(where)), mNoun(std::move(noun)), mMaxDepth(maxDepth) {}

    bool null() override { return value(); }
    bool boolean(bool) override { return value(); }
    bool number_integer(number_integer_t) override { return value(); }
    bool number_unsigned(number_unsigned_t) override { return value(); }
    bool number_float(number_float_t, const string_t&) override { return value(); }
    bool string(string_t&) override { return value(); }
    bool binary(binary_t&) override { return value(); }
    bool start_object(std::size_t) override { return open(false); }
    bool start_array(std::size_t) override { return open(true); }
    bool end_object() override { return close(); }
    bool end_array() override { return close(); }
    bool key(string_t& k) override
    {
        mStack.back().key = mStack.back().path.empty() ? k : mStack.back().path + "." + k;
        return true;
    }
    bool parse_error(std::size_t, const std::string& token, const nlohmann::detail::exception& e) override
    {
        const std::string at = path();
        if (e.id == 406) {  // out_of_range: a number the lexer read but a double cannot hold
            mError = mWhere + ": " + at + ": number " + token + " is beyond the range of a double (numbers must be finite)";
        } else {
            // nlohmann's message without its "[json.exception.parse_error.101] " code.
            std::string what = e.what();
            if (const std::size_t b = what.find("] "); what.rfind("[json.exception.", 0) == 0 && b != std::string::npos) what = what.substr(b + 2);
            mError = mWhere + ": " + at + ": not valid JSON: " + what;
        }
        return false;
    }
    const std::string& error() const { return mError; }

private:
    struct Level { std::string path, key; bool array = false; std::size_t next = 0; };

    /// The key path of the value about to be read ("guides[3].pieces", "(top level)").
    std::string path() const
    {
        if (mStack.empty()) return "(top level)";
        const Level& l = mStack.back();
        if (l.array) return l.path + "[" + std::to_string(l.next) + "]";
        return l.key.empty() ? (l.path.empty() ? std::string("(top level)") : l.path) : l.key;
    }
    bool value()
    {
        if (!mStack.empty() && mStack.back().array) ++mStack.back().next;
        return true;
    }
    bool open(bool array)
    {
        const std::string p = mStack.empty() ? std::string() : path();
        if (mStack.size() >= mMaxDepth) {
            mError = mWhere + ": " + p + ": nested " + std::to_string(mStack.size() + 1) +
                     " levels deep; " + mNoun + " nests at most " + std::to_string(mMaxDepth) + " levels of arrays and objects";
            return false;
        }
        mStack.push_back({p, std::string(), array, 0});
        return true;
    }
    bool close()
    {
        mStack.pop_back();
        return value();
    }

    std::string mWhere, mNoun, mError;
    std::size_t mMaxDepth;
    std::vector<Level> mStack;
};

} // namespace

nlohmann::json parseJsonChecked(const std::vector<char>& bytes, const std::string& where, std::size_t maxDepth,
                                const std::string& noun)
{
    JsonTextCheck check(where, maxDepth, noun);
    if (!nlohmann::json::sax_parse(bytes.begin(), bytes.end(), &check)) throw FormatError(check.error());
    try {
        return nlohmann::json::parse(bytes.begin(), bytes.end());
    } catch (const nlohmann::json::exception& e) {
        throw FormatError(where + ": not valid JSON (" + std::string(e.what()) + ")");  // the check above found none
    }
}

nlohmann::json readJsonFile(const std::string& path, std::size_t maxDepth, const std::string& noun)
{
    return parseJsonChecked(readFileBytes(path, path), path, maxDepth, noun);
}

} // namespace vdbhair
