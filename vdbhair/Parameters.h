/// @file Parameters.h
/// @brief A verb's parameters declared once: name, type, default, unit, range and help, and how
/// each reads and writes its value in the verb's parameter struct. The command line's options,
/// `--help`, Python's keywords and signature, and docs/cli.md's option tables are all made from
/// one declaration (apps/ParamOptions.h, python/src/Params.h, parameterMarkdown()), as vdb_tool's
/// action table and Blender's node declarations are, so they agree by construction.
///
/// A parameter's name is words joined by '-': the command line's `--outlier-start`, Python's
/// `outlier_start`. Its default is whatever the struct's own initializers give (P{}): a default
/// is never restated here.
#pragma once

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Types.h>
#include <vdbhair/io/AxisName.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace vdbhair {

/// @brief An axis as a person types it: "auto" for the zero vector, a unit axis by name (x, ...,
/// -z), any other vector as "(x, y, z)".
inline std::string axisText(const Vec3d& v)
{
    if (v == Vec3d(0.0)) return "auto";
    for (const std::string& name : axisNames()) if (axisFromName(name, "axis") == v) return name;
    return "(" + formatNumber(v.x()) + ", " + formatNumber(v.y()) + ", " + formatNumber(v.z()) + ")";
}

/// Reads and writes one value of type T in a parameter struct P.
template<typename P, typename T>
struct ParamAccess
{
    std::function<T(const P&)> get;
    std::function<void(P&, T)> set;
};

/// One parameter of a verb whose parameters are a struct P.
template<typename P>
struct Param
{
    std::string name;  ///< words joined by '-' (see the file comment)
    std::string help;  ///< what it does, one sentence without its unit, range or default
    std::string unit;  ///< "world units", "degrees", "voxels", "bytes", or "" for a pure number
    /// int, uint64 (counts and byte sizes), double, bool (a flag), string (one of @c choices) or
    /// an axis (a direction: by name, x to -z, or "auto" for the zero vector when @c zeroMeans says
    /// what the library picks then; Python also takes any (x, y, z); makeAxisParam())
    std::variant<ParamAccess<P, int>, ParamAccess<P, std::uint64_t>, ParamAccess<P, double>, ParamAccess<P, bool>,
                 ParamAccess<P, std::string>, ParamAccess<P, Vec3d>>
        access;
    double min = -std::numeric_limits<double>::infinity();  ///< inclusive bounds of a number
    double max = std::numeric_limits<double>::infinity();
    bool aboveMin = false;             ///< the minimum itself is excluded (a positive number)
    std::vector<std::string> choices;  ///< the names a string parameter takes
    std::string zeroMeans;             ///< what 0 stands for when it picks a value ("suggestVoxelSize()")
    /// A bool given as a value on the command line (`--roll false`), not a flag that turns it on.
    bool valued = false;
    std::string keyword;  ///< Python's keyword when the name is not one (`lambda_` for `lambda`)
    std::string shortFlag;  ///< the command line's one-letter alias ("-j"), or none
    /// Python's default is None, which leaves the struct's default (what @c zeroMeans says), as
    /// `neighbors=None` does; the value itself (0) is taken too.
    bool pythonNone = false;
    /// Older spellings of the flag that the command line still takes (`--keep-base-detail`).
    std::vector<std::string> oldFlags;
    /// A string of several values: the command line's option repeats (`--threshold 2:20
    /// --threshold 3:30`), Python takes one str or a sequence of them; the values are joined by spaces.
    bool repeats = false;

    /// Whether it is an axis (makeAxisParam()).
    bool isAxis() const { return std::holds_alternative<ParamAccess<P, Vec3d>>(access); }
    /// The keyword Python spells it as.
    std::string pythonName() const
    {
        if (!keyword.empty()) return keyword;
        std::string s = name;
        for (char& c : s) if (c == '-') c = '_';
        return s;
    }
    /// The command line's flag: `--name`, or `--no-name` for a bool flag that is on by default
    /// (it can only be turned off).
    std::string flag() const
    {
        const auto* b = std::get_if<ParamAccess<P, bool>>(&access);
        return b && !valued && b->get(P{}) ? "--no-" + name : "--" + name;
    }
    /// The default, as a person types it: 0.5, 3, true, consistent.
    std::string defaultText() const { return valueText(P{}); }
    /// The value of @a p as a person types it.
    std::string valueText(const P& p) const
    {
        return std::visit([&](const auto& a) -> std::string {
            using T = std::decay_t<decltype(a.get(p))>;
            if constexpr (std::is_same_v<T, std::string>) return a.get(p);
            else if constexpr (std::is_same_v<T, bool>) return a.get(p) ? "true" : "false";
            else if constexpr (std::is_same_v<T, double>) return formatNumber(a.get(p));
            else if constexpr (std::is_same_v<T, Vec3d>) return axisText(a.get(p));
            else return std::to_string(a.get(p));
        }, access);
    }
};

template<typename P>
using ParamTable = std::vector<Param<P>>;

/// @brief A parameter with its name, help, unit and accessors; range and choices are set after.
template<typename P, typename A>
Param<P> makeParam(std::string name, std::string help, std::string unit, A access)
{
    Param<P> p;
    p.name = std::move(name);
    p.help = std::move(help);
    p.unit = std::move(unit);
    p.access = std::move(access);
    return p;
}

/// @brief Accessors of the member that @a field returns a reference to (a lambda P& -> T&).
template<typename P, typename F>
auto member(F field)
{
    using T = std::remove_reference_t<decltype(field(std::declval<P&>()))>;
    return ParamAccess<P, T>{[field](const P& p) { return field(const_cast<P&>(p)); }, [field](P& p, T v) { field(p) = v; }};
}

/// @brief Accessors of an enumeration through its name functions (refineModeName(), ...).
template<typename P, typename F, typename NameFn, typename FromNameFn>
ParamAccess<P, std::string> named(F field, NameFn name, FromNameFn fromName)
{
    return {[field, name](const P& p) { return std::string(name(field(const_cast<P&>(p)))); },
            [field, fromName](P& p, std::string v) { field(p) = fromName(v); }};
}

/// @brief An axis parameter of the Vec3d member that @a field returns: the command line takes
/// its names (x, y, z, -x, -y, -z, and "auto" when @a autoMeans says what the zero vector stands
/// for), Python those names or any (x, y, z) (None: the default).
template<typename P, typename F>
Param<P> makeAxisParam(std::string name, std::string help, F field, std::string autoMeans = "")
{
    Param<P> p = makeParam<P>(std::move(name), std::move(help), "", member<P>(field));
    p.zeroMeans = std::move(autoMeans);
    if (!p.zeroMeans.empty()) p.choices.push_back("auto");
    for (const std::string& n : axisNames()) p.choices.push_back(n);
    p.pythonNone = !p.zeroMeans.empty();
    return p;
}

/// @brief The axis named @a text ("auto": the zero vector, when @a param takes it).
/// @throw ValueError "<who> 'w': must be one of auto, x, y, z, -x, -y, -z".
template<typename P>
Vec3d axisFromText(const Param<P>& param, const std::string& text, const std::string& who)
{
    if (text == "auto" && !param.zeroMeans.empty()) return Vec3d(0.0);
    for (const std::string& n : axisNames()) if (n == text) return axisFromName(n, who);
    std::string list;
    for (const std::string& c : param.choices) list += (list.empty() ? "" : ", ") + c;
    throw ValueError(who + " '" + text + "': must be one of " + list);
}

/// @brief The parameters of @a inner named in @a names (all when empty), declared once for a
/// struct Inner, as parameters of a struct Outer that holds an Inner (@a part: Outer& -> Inner&):
/// a verb whose parameters contain another's reuses its declaration instead of restating it.
template<typename Outer, typename Inner, typename F>
ParamTable<Outer> nestedParams(const ParamTable<Inner>& inner, F part, const std::vector<std::string>& names = {})
{
    ParamTable<Outer> out;
    auto wanted = [&](const std::string& n) {
        if (names.empty()) return true;
        for (const std::string& w : names) if (w == n) return true;
        return false;
    };
    for (const Param<Inner>& p : inner) {
        if (!wanted(p.name)) continue;
        Param<Outer> q;
        q.name = p.name;
        q.help = p.help;
        q.unit = p.unit;
        q.min = p.min;
        q.max = p.max;
        q.aboveMin = p.aboveMin;
        q.choices = p.choices;
        q.zeroMeans = p.zeroMeans;
        q.valued = p.valued;
        q.keyword = p.keyword;
        q.shortFlag = p.shortFlag;
        q.pythonNone = p.pythonNone;
        q.oldFlags = p.oldFlags;
        q.repeats = p.repeats;
        std::visit([&](const auto& a) {
            using T = std::decay_t<decltype(a.get(std::declval<const Inner&>()))>;
            q.access = ParamAccess<Outer, T>{[a, part](const Outer& o) { return a.get(part(const_cast<Outer&>(o))); },
                                             [a, part](Outer& o, T v) { a.set(part(o), v); }};
        }, p.access);
        out.push_back(std::move(q));
    }
    return out;
}

/// How an error names a parameter: the command line's flag or Python's keyword.
enum class ParamSpelling { Flag, Keyword };

template<typename P>
std::string spelled(const Param<P>& param, ParamSpelling spelling)
{
    return spelling == ParamSpelling::Flag ? param.flag() : param.pythonName();
}

/// @brief The parameter of @a table called @a name, or null.
template<typename P>
const Param<P>* findParam(const ParamTable<P>& table, const std::string& name)
{
    for (const Param<P>& p : table) if (p.name == name) return &p;
    return nullptr;
}

/// A parameter as a message names it, in each front end's spelling: the command line's flag and
/// Python's keyword (paramName() takes both from a declaration).
struct ParamName
{
    std::string flag, keyword;
};

inline std::string spelled(const ParamName& name, ParamSpelling spelling)
{
    return spelling == ParamSpelling::Flag ? name.flag : name.keyword;
}

template<typename P>
ParamName paramName(const Param<P>& param)
{
    return {param.flag(), param.pythonName()};
}

/// @brief The names of @a table's parameter @a name.
/// @throw std::logic_error when @a table declares no such parameter (a mistake in the library).
template<typename P>
ParamName paramName(const ParamTable<P>& table, const std::string& name)
{
    if (const Param<P>* p = findParam(table, name)) return paramName(*p);
    throw std::logic_error("paramName: no declared parameter '" + name + "'");
}

/// @brief A message that names parameters: its text with each parameter kept apart (a ParamName),
/// so that each front end spells them its own way (spelled()) and no front end rewrites text.
class ParamText
{
public:
    /// Some text, or a parameter.
    struct Part
    {
        Part(std::string t) : text(std::move(t)) {}
        Part(const char* t) : text(t) {}
        Part(ParamName n) : name(std::move(n)), isName(true) {}
        std::string text;
        ParamName name;
        bool isName = false;
    };
    ParamText(std::initializer_list<Part> parts) : mParts(parts) {}
    ParamText& operator+=(const Part& part)
    {
        mParts.push_back(part);
        return *this;
    }
    ParamText& operator+=(const ParamText& more)
    {
        mParts.insert(mParts.end(), more.mParts.begin(), more.mParts.end());
        return *this;
    }
    std::string spelled(ParamSpelling spelling) const
    {
        std::string out;
        for (const Part& p : mParts) out += p.isName ? vdbhair::spelled(p.name, spelling) : p.text;
        return out;
    }

private:
    std::vector<Part> mParts;
};

/// What an error that names parameters holds (ParamError): its message as a ParamText.
class ParamMessage
{
public:
    explicit ParamMessage(ParamText text) : mText(std::move(text)) {}
    virtual ~ParamMessage() = default;
    const ParamText& text() const { return mText; }

private:
    ParamText mText;
};

/// @brief An error of type @a Base (ValueError, LimitError, IoError, ...) whose message names
/// parameters: what() spells them in @a whatSpelling (Python's keywords unless told), and
/// spelledMessage() in a front end's own.
template<typename Base = ValueError>
class ParamError : public Base, public ParamMessage
{
public:
    explicit ParamError(ParamText text, ParamSpelling whatSpelling = ParamSpelling::Keyword)
        : Base(text.spelled(whatSpelling)), ParamMessage(std::move(text))
    {}
};

/// @brief The message of @a e for a front end: a ParamError's parameters spelled in @a spelling
/// (the command line's flags, Python's keywords), any other error's what().
inline std::string spelledMessage(const std::exception& e, ParamSpelling spelling)
{
    if (const auto* m = dynamic_cast<const ParamMessage*>(&e)) return m->text().spelled(spelling);
    return e.what();
}

/// @brief Check every number of @a p against its declared range (and finiteness) and every
/// string against its choices.
/// @throw ParamError<ValueError> "<where>: <--flag|keyword> <value>: must be between <min> and <max> <unit>",
/// its what() in @a spelling.
template<typename P>
void checkParams(const ParamTable<P>& table, const P& p, ParamSpelling spelling, const std::string& where)
{
    for (const Param<P>& param : table) {
        std::visit([&](const auto& a) {
            using T = std::decay_t<decltype(a.get(p))>;
            const std::string prefix = where.empty() ? std::string() : where + ": ";
            const ParamName name = paramName(param);
            if constexpr (std::is_same_v<T, std::string>) {
                const std::string v = a.get(p);
                if (param.choices.empty()) return;
                for (const std::string& c : param.choices) if (c == v) return;
                std::string list;
                for (const std::string& c : param.choices) list += (list.empty() ? "" : ", ") + c;
                throw ParamError<ValueError>({prefix, name, " '" + v + "': must be one of " + list}, spelling);
            } else if constexpr (std::is_same_v<T, Vec3d>) {
                const Vec3d v = a.get(p);
                if (!std::isfinite(v.x()) || !std::isfinite(v.y()) || !std::isfinite(v.z()))
                    throw ParamError<ValueError>({prefix, name, " " + axisText(v) + ": must be a finite vector"}, spelling);
                if (v == Vec3d(0.0) && param.zeroMeans.empty())
                    throw ParamError<ValueError>({prefix, name, " (0, 0, 0): must be a non-zero vector"}, spelling);
            } else if constexpr (!std::is_same_v<T, bool>) {
                const double v = double(a.get(p));
                if (std::isfinite(v) && (param.aboveMin ? v > param.min : v >= param.min) && v <= param.max) return;
                std::string rule = "must be ";
                if (param.aboveMin) rule += "above " + formatNumber(param.min) + (std::isfinite(param.max) ? " and at most " + formatNumber(param.max) : "");
                else if (std::isfinite(param.min) && std::isfinite(param.max)) rule += "between " + formatNumber(param.min) + " and " + formatNumber(param.max);
                else if (std::isfinite(param.min)) rule += "at least " + formatNumber(param.min);
                else if (std::isfinite(param.max)) rule += "at most " + formatNumber(param.max);
                else rule += "finite";
                if (!param.unit.empty()) rule += " " + param.unit;
                throw ParamError<ValueError>({prefix, name, " " + param.valueText(p) + ": " + rule}, spelling);
            }
        }, param.access);
    }
}

/// @brief The help line of a parameter: its help, then its unit, range, choices and what 0 means.
template<typename P>
std::string paramHelp(const Param<P>& param)
{
    std::string h = param.help;
    std::vector<std::string> notes;
    if (!param.unit.empty()) notes.push_back(param.unit);
    if (param.aboveMin) notes.push_back("above " + formatNumber(param.min) + (std::isfinite(param.max) ? ", at most " + formatNumber(param.max) : ""));
    else if (std::isfinite(param.min) && std::isfinite(param.max)) notes.push_back(formatNumber(param.min) + " to " + formatNumber(param.max));
    else if (std::isfinite(param.min)) notes.push_back("at least " + formatNumber(param.min));
    if (!param.choices.empty()) {
        std::string list;
        for (const std::string& c : param.choices) list += (list.empty() ? "" : ", ") + c;
        notes.push_back("one of " + list);
    }
    if (!param.zeroMeans.empty()) notes.push_back((param.isAxis() ? "auto: " : "0: ") + param.zeroMeans);
    if (!notes.empty()) {
        h += " (";
        for (std::size_t i = 0; i < notes.size(); ++i) h += (i ? "; " : "") + notes[i];
        h += ")";
    }
    return h;
}

/// @brief docs/cli.md's table of @a table: option, Python keyword, default, what it does.
template<typename P>
std::string parameterMarkdown(const ParamTable<P>& table)
{
    std::string out = "| option | Python | default | what it does |\n| --- | --- | --- | --- |\n";
    for (const Param<P>& p : table) {
        out += "| `" + p.flag() + "` | `" + p.pythonName() + "` | " + p.defaultText() + (p.pythonNone ? " (Python: None)" : "") + " | " +
               paramHelp(p) + " |\n";
    }
    return out;
}

} // namespace vdbhair
