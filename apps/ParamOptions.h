/// @file ParamOptions.h
/// @brief A verb's declared parameters (vdbhair/Parameters.h) as command-line options: one
/// `--name` each, its help, default and unit from the declaration, set on the verb's parameter
/// struct as it is parsed; checkParamOptions() then checks their ranges.
#pragma once

#include <CLI/CLI.hpp>

#include <vdbhair/Parameters.h>

#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

namespace vdbhair::app {

/// @brief Add an option for every parameter of @a table but those named in @a skip, each writing
/// into @a target (which must outlive parsing): `--name VALUE`, or a flag for a bool (Param::flag()).
template<typename P>
void addParamOptions(CLI::App* sub, P& target, const ParamTable<P>& table, const std::vector<std::string>& skip = {})
{
    for (const Param<P>& param : table) {
        if (std::find(skip.begin(), skip.end(), param.name) != skip.end()) continue;
        std::string flag = param.flag() + (param.shortFlag.empty() ? "" : "," + param.shortFlag);
        for (const std::string& old : param.oldFlags) flag += "," + old;
        const std::string help = paramHelp(param);
        std::visit([&](const auto& a) {
            using T = std::decay_t<decltype(a.get(target))>;
            if constexpr (std::is_same_v<T, bool>) {
                if (!param.valued) {
                    // A flag turns on what is off by default, --no-NAME turns off what is on.
                    const bool on = !a.get(P{});
                    std::string off = help;
                    if (!off.empty()) off[0] = char(std::tolower(static_cast<unsigned char>(off[0])));
                    sub->add_flag_callback(flag, [&target, a, on] { a.set(target, on); }, on ? help : "Turn off: " + off);
                    return;
                }
            }
            if constexpr (std::is_same_v<T, Vec3d>) {
                // An axis by name (makeAxisParam()).
                CLI::Option* o = sub->add_option_function<std::string>(
                    flag, [&target, a, param](const std::string& v) { a.set(target, axisFromText(param, v, param.flag())); }, help);
                o->default_str(param.defaultText());
                o->check(CLI::IsMember(param.choices));
            } else if constexpr (std::is_same_v<T, std::string>) {
                // A setter that reads text (compare's --unit) throws for a bad value: a one-line
                // parse error naming the flag.
                auto set = [&target, a](const std::string& v) {
                    try {
                        a.set(target, v);
                    } catch (const ValueError& e) {
                        throw CLI::ValidationError(spelledMessage(e, ParamSpelling::Flag));
                    }
                };
                CLI::Option* o = param.repeats ? sub->add_option_function<std::vector<std::string>>(
                                                     flag,
                                                     [set](const std::vector<std::string>& v) {
                                                         std::string all;
                                                         for (const std::string& s : v) all += (all.empty() ? "" : " ") + s;
                                                         set(all);
                                                     },
                                                     help)
                                               : sub->add_option_function<std::string>(flag, set, help);
                o->default_str(param.defaultText());
                if (!param.choices.empty()) o->check(CLI::IsMember(param.choices));
            } else {
                CLI::Option* o = sub->add_option_function<T>(flag, [&target, a](const T& v) { a.set(target, v); }, help);
                o->default_str(param.defaultText());
                if constexpr (std::is_same_v<T, std::uint64_t>) {
                    // CLI11 would read "-2" as 2^64 - 2: a count refuses a sign.
                    o->check(CLI::Validator(
                        [](std::string& v) { return !v.empty() && v[0] == '-' ? "Value " + v + " is negative (a count is 0 or more)" : std::string(); },
                        ""));
                    if (param.unit == "bytes") o->transform(CLI::AsSizeValue(false));
                }
            }
        }, param.access);
    }
}

/// @brief The parameters of @a table named in @a names, in the table's order: the part of a shared
/// declaration that a verb offers (`--strict` of the reading options).
template<typename P>
ParamTable<P> selectParams(const ParamTable<P>& table, const std::vector<std::string>& names)
{
    ParamTable<P> out;
    for (const Param<P>& p : table) if (std::find(names.begin(), names.end(), p.name) != names.end()) out.push_back(p);
    return out;
}

/// @brief Check the declared ranges of @a p, errors naming the flags ("--levels 9: must be ...").
template<typename P>
void checkParamOptions(const ParamTable<P>& table, const P& p)
{
    checkParams(table, p, ParamSpelling::Flag, "");
}

} // namespace vdbhair::app
