/// @file Params.h
/// @brief Python functions made from a verb's declared parameters (vdbhair/Parameters.h): their
/// keywords, defaults, annotations and the docstring's Args come from the declaration, so the
/// signature agrees with the command line's options by construction.
///
/// defineVerb() writes a small Python function with the real signature (as `dataclasses` writes
/// `__init__`), which checks the arguments' types (ArgumentTypeError, Module.cc) and hands them as
/// one dict to the C++ implementation; applyKeywords() sets the declared ones on the parameter
/// struct and checks their ranges.
#pragma once

#include "Common.h"

#include <vdbhair/Parameters.h>
#include <vdbhair/RunOptions.h>

#include <pybind11/eval.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <string>
#include <vector>

namespace vdbhair::py {

/// A keyword of a verb that is not one of its declared parameters (a head, a scalp, threads).
struct PyKeyword
{
    std::string name;
    std::string annotation;  ///< as Module.cc's checks read it ("int", "Optional[str]", ...); "" for any
    pyb::object defaultValue;
    std::string doc;  ///< its line in Args (without the name)
};

/// The annotation a declared parameter is checked by.
template<typename P>
std::string pythonAnnotation(const Param<P>& param)
{
    const std::string type = std::visit([&param](const auto& a) -> std::string {
        using T = std::decay_t<decltype(a.get(std::declval<const P&>()))>;
        if constexpr (std::is_same_v<T, std::string>) return param.repeats ? "Union[str, Sequence[str]]" : "str";
        else if constexpr (std::is_same_v<T, bool>) return "bool";
        else if constexpr (std::is_same_v<T, double>) return "float";
        else if constexpr (std::is_same_v<T, Vec3d>) return "Union[str, Tuple[float, float, float]]";  // a name or a vector
        else return "int";
    }, param.access);
    return param.pythonNone ? "Optional[" + type + "]" : type;
}

/// The default of a declared parameter as a Python object.
template<typename P>
pyb::object pythonDefault(const Param<P>& param)
{
    if (param.pythonNone) return pyb::none();
    const P defaults{};
    return std::visit([&](const auto& a) -> pyb::object {
        using T = std::decay_t<decltype(a.get(defaults))>;
        if constexpr (std::is_same_v<T, Vec3d>) {
            const Vec3d v = a.get(defaults);
            return pyb::make_tuple(v.x(), v.y(), v.z());
        } else {
            return pyb::cast(a.get(defaults));
        }
    }, param.access);
}

/// @brief Set the declared parameters given in @a kw on @a p, then check their ranges.
/// @throw ValueError "<verb>: <keyword> <value>: <rule>".
template<typename P>
void applyKeywords(const ParamTable<P>& table, const pyb::dict& kw, P& p, const std::string& verb)
{
    for (const Param<P>& param : table) {
        const std::string key = param.pythonName();
        if (!kw.contains(key)) continue;
        const pyb::object v = kw[key.c_str()];
        if (v.is_none()) continue;  // Param::pythonNone: the struct's default
        std::visit([&](const auto& a) {
            using T = std::decay_t<decltype(a.get(p))>;
            if constexpr (std::is_same_v<T, std::string>) {
                std::string text;
                if (param.repeats && !pyb::isinstance<pyb::str>(v)) {
                    for (const std::string& s : v.cast<std::vector<std::string>>()) text += (text.empty() ? "" : " ") + s;
                } else {
                    text = v.cast<std::string>();
                }
                if (!param.choices.empty() && std::find(param.choices.begin(), param.choices.end(), text) == param.choices.end()) {
                    std::string list;
                    for (const std::string& c : param.choices) list += (list.empty() ? "" : ", ") + c;
                    throw ValueError(verb + ": " + key + " '" + text + "': must be one of " + list);
                }
                try {
                    a.set(p, text);  // a setter that reads text (compare's unit) names what it refuses
                } catch (const ValueError& e) {
                    throw ValueError(verb + ": " + spelledMessage(e, ParamSpelling::Keyword));
                }
            } else if constexpr (std::is_same_v<T, Vec3d>) {
                // An axis: a name, as the command line's, or any (x, y, z).
                if (pyb::isinstance<pyb::str>(v)) {
                    a.set(p, axisFromText(param, v.cast<std::string>(), verb + ": " + key));
                } else {
                    const auto xyz = v.cast<std::vector<double>>();
                    if (xyz.size() != 3) throw ValueError(verb + ": " + key + ": must be an axis name or (x, y, z), got " + std::to_string(xyz.size()) + " numbers");
                    a.set(p, Vec3d(xyz[0], xyz[1], xyz[2]));
                }
            } else if constexpr (std::is_same_v<T, std::uint64_t>) {
                const long long n = v.cast<long long>();
                if (n < 0) throw ValueError(verb + ": " + key + " " + std::to_string(n) + ": must be at least " + formatNumber(std::max(0.0, param.min)));
                a.set(p, std::uint64_t(n));
            } else {
                a.set(p, v.cast<T>());
            }
        }, param.access);
    }
    checkParams(table, p, ParamSpelling::Keyword, verb);
}

/// @brief The keyword @a name, or the value of its older spelling @a oldName when that was given
/// (a DeprecationWarning saying the new one): a keyword renamed keeps working for one release.
/// The old keyword is an extra of the verb with default None (renamedKeyword() declares it).
inline pyb::object renamedKeywordValue(const pyb::dict& kw, const std::string& name, const std::string& oldName, const std::string& verb)
{
    const pyb::object old = kw[oldName.c_str()];
    if (old.is_none()) return kw[name.c_str()];
    pyb::module_::import("warnings").attr("warn")(verb + "(" + oldName + "=...) is deprecated: use " + name + "=",
                                                  pyb::reinterpret_borrow<pyb::object>(PyExc_DeprecationWarning), 2);  // at the caller of the verb
    return old;
}

/// @brief The extra keyword of an older spelling of @a name (renamedKeywordValue()).
inline PyKeyword renamedKeyword(const std::string& oldName, const std::string& name)
{
    return {oldName, "Optional[bool]", pyb::none(), "deprecated spelling of " + name + " (a DeprecationWarning; removed in the next release)."};
}

/// @brief Define @a verb on @a m: `verb(positional..., *, <declared keywords>, <extra keywords>,
/// threads=0, progress=None)`
/// (a positional is "name" or "name: annotation", as Module.cc's type checks read annotations,
/// and "name=None" one that may be left out)
/// calling @a impl(positional..., kwargs) with every keyword in one dict.
/// @param summary the docstring's first paragraphs; @a positionalDoc and @a returns its other parts
/// @param positionalKeywords how many of the first declared parameters may also be given by position
template<typename P>
void defineVerb(pyb::module_& m, const std::string& verb, const std::vector<std::string>& positional, const ParamTable<P>& table,
                const std::vector<PyKeyword>& extras, const std::string& summary, const std::string& positionalDoc,
                const std::string& returns, const pyb::cpp_function& impl, std::size_t positionalKeywords = 0)
{
    struct Keyword { std::string name, annotation; pyb::object value; std::string doc; };
    std::vector<Keyword> keywords;
    for (const Param<P>& p : table) keywords.push_back({p.pythonName(), pythonAnnotation(p), pythonDefault(p), paramHelp(p)});
    for (const PyKeyword& k : extras) keywords.push_back({k.name, k.annotation, k.defaultValue, k.doc});
    // What every long operation takes (Common.h's runLong()).
    for (const Param<RunOptions>& p : runParameters()) keywords.push_back({p.pythonName(), pythonAnnotation(p), pythonDefault(p), paramHelp(p)});
    keywords.push_back({"progress", "Optional[Callable]", pyb::none(),
                        "optional callable ``progress(stage, done, total, unit)``, called at each stage's start and then at most "
                        "ten times a second; raising in it stops the work."});

    std::string doc = summary + "\n\nArgs:\n" + positionalDoc;
    for (const Keyword& k : keywords) doc += "    " + k.name + ": " + k.doc + "\n";
    doc += "\nReturns:\n    " + returns;

    pyb::dict scope;
    std::string args, checks, dict, head, params;
    // A positional argument is "name" or "name: annotation" (checked as the keywords are), or
    // "name=None", which may be left out.
    for (const std::string& given : positional) {
        const bool optional = given.size() > 5 && given.compare(given.size() - 5, 5, "=None") == 0;
        const std::string p = optional ? given.substr(0, given.size() - 5) : given;
        const std::size_t colon = p.find(':');
        const std::string name = p.substr(0, colon);
        head += name + ", ";
        params += name + (optional ? "=None, " : ", ");
        if (colon != std::string::npos) checks += "(\"" + name + "\", \"" + p.substr(p.find_first_not_of(' ', colon + 1)) + "\", " + name + "), ";
    }
    for (std::size_t i = 0; i < keywords.size(); ++i) {
        const Keyword& k = keywords[i];
        const std::string d = "_d" + std::to_string(i);
        scope[d.c_str()] = k.value;
        args += (i == positionalKeywords ? ", *, " : ", ") + k.name + "=" + d;
        if (!k.annotation.empty()) checks += "(\"" + k.name + "\", \"" + k.annotation + "\", " + k.name + "), ";
        dict += "\"" + k.name + "\": " + k.name + ", ";
    }
    scope["_impl"] = impl;
    scope["_doc"] = doc;
    scope["_module"] = m;
    const std::string source = "def _make():\n"
                               "    _g = vars(_module)\n"
                               "    def " + verb + "(" + params.substr(0, params.size() - 2) + args + "):\n"
                               "        _g['_check_keywords'](\"" + verb + "\", (" + checks + "))\n"
                               "        return _impl(" + head + "{" + dict + "})\n"
                               "    " + verb + ".__doc__ = _doc\n"
                               "    " + verb + ".__module__ = 'vdbhair'\n"
                               "    " + verb + ".__qualname__ = '" + verb + "'\n"
                               "    return " + verb + "\n"
                               "_result = _make()\n";
    pyb::exec(source, scope);
    m.attr(verb.c_str()) = scope["_result"];
}

} // namespace vdbhair::py
