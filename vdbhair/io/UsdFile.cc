#include "UsdFile.h"

#include <vdbhair/Memory.h>
#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/FreeFormCurve.h>
#include <vdbhair/io/Xform.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <functional>
#include <map>

namespace vdbhair {

namespace {

// ---------------------------------------------------------------------------------------------
// Tokens of the USD text format: punctuation, identifiers (with ':' '.' and a trailing "[]"),
// numbers, strings, paths <...> and asset paths @...@; '#' starts a comment.

enum class Tok { End, Punct, Word, Number, String, Path };

struct Token
{
    Tok kind = Tok::End;
    std::string_view text;  ///< the characters (a string's without its quotes)
    double number = 0.0;
    std::size_t line = 0;
};

class UsdLexer
{
public:
    UsdLexer(const std::vector<char>& bytes, std::string where) : mData(bytes.data()), mSize(bytes.size()), mWhere(std::move(where))
    {
        // The magic line.
        static const char kMagic[] = "#usda";
        if (mSize >= 8 && std::memcmp(mData, "PXR-USDC", 8) == 0) {
            throw UnsupportedError(mWhere + ": a binary USD (crate, PXR-USDC) file; vdbhair reads USD text (USDA, in a .usda or .usd "
                                   "file): convert it first with 'usdcat in.usd -o out.usda'");
        }
        if (mSize < 5 || std::memcmp(mData, kMagic, 5) != 0) {
            throw FormatError(mWhere + ": line 1: not a USD text file: it must start with '#usda 1.0'"
                              " (binary .usdc files are not read)");
        }
        while (mPos < mSize && mData[mPos] != '\n') ++mPos;
        advance();
    }

    const Token& peek() const { return mTok; }
    Token next()
    {
        Token t = mTok;
        advance();
        return t;
    }
    bool isPunct(char c) const { return mTok.kind == Tok::Punct && mTok.text[0] == c; }
    bool isWord(std::string_view w) const { return mTok.kind == Tok::Word && mTok.text == w; }
    void expect(char c, const std::string& context)
    {
        if (!isPunct(c)) fail(std::string("expected '") + c + "' " + context + ", found " + describe(mTok));
        advance();
    }
    [[noreturn]] void fail(const std::string& msg) const
    {
        throw FormatError(mWhere + ": line " + std::to_string(mTok.line) + ": " + msg);
    }
    static std::string describe(const Token& t)
    {
        switch (t.kind) {
        case Tok::End: return "the end of the file";
        case Tok::String: return "the string \"" + std::string(t.text.substr(0, 40)) + "\"";
        default: return "'" + std::string(t.text.substr(0, 40)) + "'";
        }
    }
    const std::string& where() const { return mWhere; }

private:
    static bool isWordStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
    static bool isWordChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == ':' || c == '.'; }

    void advance()
    {
        // Skip blanks and comments, counting lines.
        for (;;) {
            while (mPos < mSize && std::isspace(static_cast<unsigned char>(mData[mPos]))) {
                if (mData[mPos] == '\n') ++mLine;
                ++mPos;
            }
            if (mPos < mSize && mData[mPos] == '#') {
                while (mPos < mSize && mData[mPos] != '\n') ++mPos;
                continue;
            }
            break;
        }
        mTok = Token{};
        mTok.line = mLine;
        if (mPos >= mSize) return;
        const char c = mData[mPos];
        const std::size_t start = mPos;
        if (c == '"' || c == '\'') {
            const bool triple = mPos + 2 < mSize && mData[mPos + 1] == c && mData[mPos + 2] == c;
            const std::size_t q = triple ? 3 : 1;
            mPos += q;
            const std::size_t body = mPos;
            for (;;) {
                if (mPos >= mSize) {
                    mTok.line = mLine;
                    fail("a string that starts on this line never ends");
                }
                if (mData[mPos] == '\\') { mPos += 2; continue; }
                if (mData[mPos] == '\n') ++mLine;
                if (mData[mPos] == c && (!triple || (mPos + 2 < mSize && mData[mPos + 1] == c && mData[mPos + 2] == c))) break;
                ++mPos;
            }
            mTok.kind = Tok::String;
            mTok.text = std::string_view(mData + body, mPos - body);
            mPos += q;
            return;
        }
        if (c == '<' || c == '@') {
            const char close = c == '<' ? '>' : '@';
            ++mPos;
            while (mPos < mSize && mData[mPos] != close && mData[mPos] != '\n') ++mPos;
            if (mPos >= mSize || mData[mPos] != close) fail(std::string("a ") + (c == '<' ? "path <...>" : "asset path @...@") + " is not closed on its line");
            ++mPos;
            mTok.kind = Tok::Path;
            mTok.text = std::string_view(mData + start, mPos - start);
            return;
        }
        if (std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.') {
            std::size_t p = mPos;
            if (mData[p] == '+') ++p;
            double v = 0.0;
            const auto res = std::from_chars(mData + p, mData + mSize, v);
            if (res.ec == std::errc() && res.ptr > mData + p) {
                mPos = std::size_t(res.ptr - mData);
                mTok.kind = Tok::Number;
                mTok.number = v;
                mTok.text = std::string_view(mData + start, mPos - start);
                return;
            }
            if (c == '-' && mPos + 1 < mSize && isWordStart(mData[mPos + 1])) {  // -inf
                ++mPos;
                while (mPos < mSize && isWordChar(mData[mPos])) ++mPos;
                mTok.kind = Tok::Number;
                mTok.text = std::string_view(mData + start, mPos - start);
                mTok.number = mTok.text == "-inf" ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::quiet_NaN();
                return;
            }
        }
        if (isWordStart(c)) {
            while (mPos < mSize && isWordChar(mData[mPos])) ++mPos;
            if (mPos + 1 < mSize && mData[mPos] == '[' && mData[mPos + 1] == ']') mPos += 2;  // int[], point3f[]
            mTok.kind = Tok::Word;
            mTok.text = std::string_view(mData + start, mPos - start);
            if (mTok.text == "inf" || mTok.text == "nan") {
                mTok.kind = Tok::Number;
                mTok.number = mTok.text == "inf" ? std::numeric_limits<double>::infinity() : std::numeric_limits<double>::quiet_NaN();
            }
            return;
        }
        if (std::strchr("()[]{}=,:;", c)) {
            ++mPos;
            mTok.kind = Tok::Punct;
            mTok.text = std::string_view(mData + start, 1);
            return;
        }
        mTok.line = mLine;
        fail(std::string("unexpected character '") + c + "'");
    }

    const char* mData;
    std::size_t mSize, mPos = 0, mLine = 1;
    std::string mWhere;
    Token mTok;
};

// ---------------------------------------------------------------------------------------------
// Values, flattened: every number in order, every string or word, how many top-level elements.

/// Values and prims nest at most this deep: the parser recurses once per level, so a file
/// cannot run it out of stack (real files nest values 2-3 deep and prims a few tens).
constexpr int kMaxNesting = 128;

void checkNesting(const UsdLexer& lex, int depth, const char* what)
{
    if (depth > kMaxNesting) {
        lex.fail(std::string(what) + " nested more than " + std::to_string(kMaxNesting) + " deep; USD text here nests at most " +
                 std::to_string(kMaxNesting) + " levels");
    }
}

struct FlatValue
{
    std::vector<double> numbers;
    std::vector<std::string> words;
    std::size_t elements = 0;  ///< top-level array elements (1 for a scalar)
    bool array = false;
    std::size_t line = 0;
};

void parseValueInto(UsdLexer& lex, FlatValue& v, int depth)
{
    checkNesting(lex, depth, "values");
    const Token& t = lex.peek();
    if (t.kind == Tok::Number) { v.numbers.push_back(lex.next().number); return; }
    if (t.kind == Tok::String || t.kind == Tok::Word || t.kind == Tok::Path) { v.words.emplace_back(lex.next().text); return; }
    if (t.kind == Tok::Punct && (t.text[0] == '[' || t.text[0] == '(' || t.text[0] == '{')) {
        const char open = t.text[0];
        const char close = open == '[' ? ']' : open == '(' ? ')' : '}';
        lex.next();
        std::size_t count = 0;
        while (!lex.isPunct(close)) {
            if (lex.peek().kind == Tok::End) lex.fail(std::string("a value that opens with '") + open + "' is not closed");
            parseValueInto(lex, v, depth + 1);
            ++count;
            if (open == '{' && lex.isPunct(':')) { lex.next(); parseValueInto(lex, v, depth + 1); }  // time samples
            if (lex.isPunct(',')) lex.next();
            else if (!lex.isPunct(close)) lex.fail(std::string("expected ',' or '") + close + "' in a value, found " + UsdLexer::describe(lex.peek()));
        }
        lex.next();
        if (depth == 0) {
            v.array = open == '[';
            v.elements = open == '[' ? count : 1;
        }
        return;
    }
    lex.fail("expected a value, found " + UsdLexer::describe(t));
}

FlatValue parseValue(UsdLexer& lex)
{
    FlatValue v;
    v.line = lex.peek().line;
    parseValueInto(lex, v, 0);
    if (!v.array) v.elements = 1;
    return v;
}

/// `( key = value ... )` metadata: the simple entries (a string, word or number), by key.
std::map<std::string, FlatValue> parseMetadata(UsdLexer& lex)
{
    std::map<std::string, FlatValue> out;
    lex.expect('(', "to open metadata");
    while (!lex.isPunct(')')) {
        if (lex.peek().kind == Tok::End) lex.fail("metadata that opens with '(' is not closed");
        if (lex.peek().kind == Tok::String) { lex.next(); continue; }  // a bare doc string
        // [prepend|append|add|delete|reorder] key = value
        std::string key;
        while (lex.peek().kind == Tok::Word) key = std::string(lex.next().text);
        if (key.empty()) lex.fail("expected a metadata key, found " + UsdLexer::describe(lex.peek()));
        lex.expect('=', "after metadata key '" + key + "'");
        out[key] = parseValue(lex);
        if (lex.isPunct(';') || lex.isPunct(',')) lex.next();
    }
    lex.next();
    return out;
}

// ---------------------------------------------------------------------------------------------
// Prims: the tree's transforms, and every BasisCurves prim's properties.

struct Property
{
    FlatValue value;
    std::string interpolation;
    bool hasValue = false;
    bool sampled = false;  ///< the value is the first of its time samples
};

constexpr std::size_t kNoParent = std::numeric_limits<std::size_t>::max();

/// A prim of the tree, for its transform: its parent and its `xformOpOrder` and `xformOp:*`.
struct PrimNode
{
    std::size_t parent = kNoParent;
    std::string name;
    std::size_t line = 0;
    std::map<std::string, Property> xformProps;
};

struct CurvesPrim
{
    std::string name;
    std::size_t line = 0;
    std::size_t node = 0;  ///< its PrimNode
    std::map<std::string, Property> props;
};

struct UsdDocument
{
    std::vector<PrimNode> nodes;
    std::vector<CurvesPrim> curves;
    std::string upAxis;
    double metersPerUnit = 0.0;  ///< 0: not in the stage's metadata
    std::size_t timeSampled = 0;  ///< properties read at their first time sample
};

/// A property's value: its default, or the first of its time samples, which win (USD resolves a
/// sampled attribute to its samples at any time; a file's first frame is what it shows first).
void store(std::map<std::string, Property>& props, const std::string& name, Property prop)
{
    Property& to = props[name];
    if (to.sampled && !prop.sampled && prop.hasValue) return;
    if (!prop.hasValue && to.hasValue) {  // a declaration without a value keeps the value
        if (!prop.interpolation.empty()) to.interpolation = prop.interpolation;
        return;
    }
    if (to.hasValue && prop.interpolation.empty()) prop.interpolation = to.interpolation;
    to = std::move(prop);
}

/// `{ TIME: VALUE, ... }`: the value at the earliest time.
FlatValue parseFirstSample(UsdLexer& lex)
{
    lex.expect('{', "to open time samples");
    FlatValue first;
    double firstTime = std::numeric_limits<double>::infinity();
    while (!lex.isPunct('}')) {
        if (lex.peek().kind != Tok::Number) lex.fail("expected a time in time samples, found " + UsdLexer::describe(lex.peek()));
        const double t = lex.next().number;
        lex.expect(':', "after a time sample's time");
        FlatValue v = parseValue(lex);
        if (t < firstTime) { firstTime = t; first = std::move(v); }
        if (lex.isPunct(',')) lex.next();
        else if (!lex.isPunct('}')) lex.fail("expected ',' or '}' in time samples, found " + UsdLexer::describe(lex.peek()));
    }
    lex.next();
    return first;
}

void parsePrimBody(UsdLexer& lex, UsdDocument& doc, CurvesPrim* curves, std::size_t node, int depth);

void parsePrim(UsdLexer& lex, UsdDocument& doc, std::size_t parent, int depth)
{
    checkNesting(lex, depth, "prims");
    const Token spec = lex.next();  // def, over, class
    std::string type;
    if (lex.peek().kind == Tok::Word) type = std::string(lex.next().text);
    if (lex.peek().kind != Tok::String) lex.fail("expected the prim's name in quotes after '" + std::string(spec.text) + "', found " + UsdLexer::describe(lex.peek()));
    const Token name = lex.next();
    if (lex.isPunct('(')) parseMetadata(lex);
    lex.expect('{', "to open the body of prim \"" + std::string(name.text) + "\"");
    const std::size_t node = doc.nodes.size();
    doc.nodes.push_back(PrimNode{parent, std::string(name.text), name.line, {}});
    if (spec.text == "def" && type == "BasisCurves") {
        CurvesPrim prim;
        prim.name = std::string(name.text);
        prim.line = name.line;
        prim.node = node;
        parsePrimBody(lex, doc, &prim, node, depth);
        doc.curves.push_back(std::move(prim));
    } else {
        parsePrimBody(lex, doc, nullptr, node, depth);
    }
}

void parsePrimBody(UsdLexer& lex, UsdDocument& doc, CurvesPrim* curves, std::size_t node, int depth)
{
    while (!lex.isPunct('}')) {
        const Token& t = lex.peek();
        if (t.kind == Tok::End) lex.fail("a prim's body is not closed with '}'");
        if (t.kind == Tok::Punct && t.text[0] == ';') { lex.next(); continue; }
        if (lex.isWord("def") || lex.isWord("over") || lex.isWord("class")) { parsePrim(lex, doc, node, depth + 1); continue; }
        if (lex.isWord("variantSet")) {  // variantSet "name" = { "a" { ... } }
            lex.next();
            lex.next();
            lex.expect('=', "after variantSet's name");
            lex.expect('{', "to open a variantSet");
            while (!lex.isPunct('}')) {
                if (lex.peek().kind != Tok::String) lex.fail("expected a variant name, found " + UsdLexer::describe(lex.peek()));
                lex.next();
                if (lex.isPunct('(')) parseMetadata(lex);
                lex.expect('{', "to open a variant");
                checkNesting(lex, depth + 1, "prims");
                parsePrimBody(lex, doc, nullptr, node, depth + 1);
            }
            lex.next();
            continue;
        }
        if (t.kind != Tok::Word) lex.fail("expected a property or a prim, found " + UsdLexer::describe(t));
        // [custom] [uniform|varying] TYPE NAME [= VALUE] [(METADATA)], or rel NAME [= TARGET]
        while (lex.isWord("custom") || lex.isWord("uniform") || lex.isWord("varying") || lex.isWord("config")) lex.next();
        std::string name;
        if (lex.isWord("rel")) {
            lex.next();
        } else {
            if (lex.peek().kind != Tok::Word) lex.fail("expected a property type, found " + UsdLexer::describe(lex.peek()));
            lex.next();
        }
        if (lex.peek().kind != Tok::Word) lex.fail("expected a property name, found " + UsdLexer::describe(lex.peek()));
        name = std::string(lex.next().text);
        const auto suffix = [&](const char* s) { return name.size() > std::strlen(s) && name.compare(name.size() - std::strlen(s), std::string::npos, s) == 0; };
        const bool samples = suffix(".timeSamples");
        if (samples) name.resize(name.size() - std::strlen(".timeSamples"));
        Property prop;
        if (lex.isPunct('=')) {
            lex.next();
            if (samples) {
                prop.value = parseFirstSample(lex);
                prop.sampled = true;
                ++doc.timeSampled;
            } else {
                prop.value = parseValue(lex);
            }
            prop.hasValue = true;
        }
        if (lex.isPunct('(')) {
            const auto meta = parseMetadata(lex);
            if (const auto it = meta.find("interpolation"); it != meta.end() && !it->second.words.empty()) prop.interpolation = it->second.words[0];
        }
        if (suffix(".connect")) continue;
        if (name.rfind("xformOp", 0) == 0) store(doc.nodes[node].xformProps, name, prop);
        if (curves) store(curves->props, name, std::move(prop));
    }
    lex.next();
}

UsdDocument parseUsda(const std::vector<char>& bytes, const std::string& where)
{
    UsdLexer lex(bytes, where);
    UsdDocument doc;
    if (lex.isPunct('(')) {
        const auto meta = parseMetadata(lex);
        if (const auto it = meta.find("upAxis"); it != meta.end() && !it->second.words.empty()) doc.upAxis = it->second.words[0];
        if (const auto it = meta.find("metersPerUnit"); it != meta.end()) {
            const FlatValue& v = it->second;
            if (v.numbers.size() != 1 || !(v.numbers[0] > 0.0) || !std::isfinite(v.numbers[0])) {
                lex.fail("metersPerUnit must be one positive number (the stage's unit in metres)");
            }
            doc.metersPerUnit = v.numbers[0];
        }
    }
    while (lex.peek().kind != Tok::End) {
        if (lex.isWord("def") || lex.isWord("over") || lex.isWord("class")) parsePrim(lex, doc, kNoParent, 1);
        else lex.fail("expected a prim (def, over or class), found " + UsdLexer::describe(lex.peek()));
    }
    return doc;
}

/// A prim's own transform: its `xformOpOrder`'s ops, the last applied first (`!invert!` inverts
/// one; `!resetXformStack!` sets @a reset: the parents' transforms do not apply).
xform::Matrix localTransform(const PrimNode& node, bool& reset, const std::string& where, const std::function<void(const std::string&)>& warn)
{
    reset = false;
    xform::Matrix local = xform::kIdentity;
    const auto order = node.xformProps.find("xformOpOrder");
    if (order == node.xformProps.end() || !order->second.hasValue) return local;  // USD applies only ordered ops
    const std::string at = "prim \"" + node.name + "\" (line " + std::to_string(order->second.value.line) + ")";
    for (const std::string& entry : order->second.value.words) {
        if (entry == "!resetXformStack!") { reset = true; continue; }
        const bool inverse = entry.rfind("!invert!", 0) == 0;
        const std::string name = inverse ? entry.substr(8) : entry;
        const auto op = node.xformProps.find(name);
        if (op == node.xformProps.end() || !op->second.hasValue) {
            warn(at + ": xformOpOrder names \"" + name + "\", which has no value; that op is not applied");
            continue;
        }
        const std::size_t colon = name.find(':', 8);
        const std::string type = name.size() > 8 ? name.substr(8, colon == std::string::npos ? std::string::npos : colon - 8) : std::string();
        xform::Matrix m;
        if (std::string rule = xform::usdOp(type, op->second.value.numbers, m); !rule.empty()) {
            throw FormatError(where + ": line " + std::to_string(op->second.value.line) + ": " + at + ": " + name + ": " + rule);
        }
        if (inverse && !xform::invert(m, m)) {
            throw FormatError(where + ": line " + std::to_string(op->second.value.line) + ": " + at + ": !invert!" + name + " is not invertible");
        }
        local = xform::multiply(m, local);
    }
    return local;
}

/// The transform from a prim's space to the stage's: its own, then its parents' up the tree.
xform::Matrix worldTransform(const UsdDocument& doc, std::size_t node, const std::string& where, const std::function<void(const std::string&)>& warn)
{
    xform::Matrix world = xform::kIdentity;
    for (std::size_t n = node; n != kNoParent; n = doc.nodes[n].parent) {
        bool reset = false;
        world = xform::multiply(world, localTransform(doc.nodes[n], reset, where, warn));
        if (reset) break;
    }
    return world;
}

/// A primvar's values as stored: per curve, per control point, or per segment end (varying).
enum class Interp { Constant, Uniform, Vertex, Varying };

struct Primvar
{
    Interp interp = Interp::Constant;
    std::size_t arity = 1;
    std::vector<float> values;
};

} // namespace

StrandSet readUsda(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readUsda(" + path + ")";
    const std::vector<char> bytes = readFileBytes(path, where, opts.interrupter);
    const UsdDocument doc = parseUsda(bytes, where);
    if (doc.curves.empty()) {
        throw FormatError(where + ": no strands: the file has no 'def BasisCurves' prim");
    }
    const std::function<void(const std::string&)> warn = [&](const std::string& w) { if (report) report->warnings.push_back(where + ": " + w); };
    if (doc.upAxis == "Z") warn("the stage's upAxis is Z; coordinates are kept as they are (render with RenderParams::up set to z)");
    if (doc.timeSampled) warn(std::to_string(doc.timeSampled) + " time-sampled attribute(s) were read at their first sample (an animation's first frame)");

    StrandSet out;
    ShortStrandFilter filter(opts, report, where);
    std::size_t strandIndex = 0;
    bool first = true;
    InterruptPoll poll(opts.interrupter, where);
    for (const CurvesPrim& prim : doc.curves) {
        poll();
        const std::string at = "prim \"" + prim.name + "\" (line " + std::to_string(prim.line) + ")";
        auto find = [&](const char* name) -> const Property* {
            const auto it = prim.props.find(name);
            return it != prim.props.end() && it->second.hasValue ? &it->second : nullptr;
        };
        auto token = [&](const char* name, const char* fallback) {
            const Property* t = find(name);
            return t && !t->value.words.empty() ? t->value.words[0] : std::string(fallback);
        };
        // USD's fallbacks: cubic Bezier curves, not periodic.
        const std::string type = token("type", "cubic"), basisName = token("basis", "bezier"), wrapName = token("wrap", "nonperiodic");
        if (type != "linear" && type != "cubic") throw FormatError(where + ": " + at + ": type \"" + type + "\"; BasisCurves are linear or cubic");
        if (wrapName != "nonperiodic" && wrapName != "periodic" && wrapName != "pinned") {
            throw FormatError(where + ": " + at + ": wrap \"" + wrapName + "\"; expected nonperiodic, periodic or pinned");
        }
        const CurveWrap wrap = wrapName == "periodic" ? CurveWrap::Periodic : wrapName == "pinned" ? CurveWrap::Pinned : CurveWrap::Nonperiodic;
        bool linear = type == "linear";
        CubicBasis basis = CubicBasis::Bezier;
        if (!linear) {
            if (basisName == "bspline") basis = CubicBasis::BSpline;
            else if (basisName == "catmullRom") basis = CubicBasis::CatmullRom;
            else if (basisName != "bezier") {
                warn(at + ": cubic basis \"" + basisName + "\" (deprecated in USD) is not evaluated; its control points are read as a polyline");
                linear = true;
            }
        }
        const Property* counts = find("curveVertexCounts");
        const Property* points = find("points");
        if (!counts) throw FormatError(where + ": " + at + ": BasisCurves without curveVertexCounts");
        if (!points) throw FormatError(where + ": " + at + ": BasisCurves without points");
        const std::vector<double>& n = counts->value.numbers;
        const std::vector<double>& p = points->value.numbers;
        if (p.size() % 3 != 0 || (points->value.array && points->value.elements * 3 != p.size())) {
            throw FormatError(where + ": line " + std::to_string(points->value.line) + ": " + at + ": points must be (x, y, z) triples");
        }
        const std::size_t nP = p.size() / 3, nC = n.size();
        std::uint64_t sum = 0, numVarying = 0;
        for (std::size_t i = 0; i < nC; ++i) {
            poll();
            if (!(n[i] >= 0.0) || n[i] != std::floor(n[i]) || n[i] > 4294967295.0) {
                throw FormatError(where + ": line " + std::to_string(counts->value.line) + ": " + at + ": curveVertexCounts[" +
                                  std::to_string(i) + "] is " + std::to_string(n[i]) + "; counts must be whole numbers of at least 0");
            }
            sum += std::uint64_t(n[i]);
            numVarying += linear ? std::uint64_t(n[i]) : cubicVaryingCount(basis, wrap, std::size_t(n[i]));
        }
        if (sum != nP) {
            throw FormatError(where + ": line " + std::to_string(counts->value.line) + ": " + at + ": curveVertexCounts add up to " +
                              std::to_string(sum) + " but there are " + std::to_string(nP) + " points");
        }
        if (!find("type") && !find("basis")) {
            // USD's fallback is cubic Bezier; curves whose counts cannot be Bezier curves were meant
            // as polylines (a writer that left the type out).
            bool bezier = true;
            for (std::size_t i = 0; i < nC && bezier; ++i) bezier = std::size_t(n[i]) >= 4 && (std::size_t(n[i]) - 1) % 3 == 0;
            if (!bezier) {
                warn(at + ": type is not authored and its curves do not fit USD's fallback (cubic Bezier: 3 k + 1 points); read as linear");
                linear = true;
                numVarying = sum;
            }
        }
        // A primvar's values with their interpolation (none: false; constant: into @a constant).
        auto readPrimvar = [&](const char* name, std::size_t arity, Primvar& pv, float* constant) {
            pv = Primvar{};
            pv.arity = arity;
            const Property* prop = find(name);
            if (!prop) return false;
            const std::vector<double>& v = prop->value.numbers;
            // The interpolation: the metadata, else an attribute NAME:interpolation (older writers),
            // else USD's fallback (vertex for widths; constant for primvars and for one width).
            std::string interp = prop->interpolation;
            if (const Property* i = interp.empty() ? find((std::string(name) + ":interpolation").c_str()) : nullptr; i && !i->value.words.empty()) {
                interp = i->value.words[0];
            }
            if (interp.empty()) interp = std::strcmp(name, "widths") == 0 && v.size() != 1 ? "vertex" : "constant";
            const std::string line = "line " + std::to_string(prop->value.line);
            auto need = [&](std::uint64_t count, const char* per) {
                if (v.size() != arity * count) {
                    throw FormatError(where + ": " + line + ": " + at + ": " + interp + " " + name + " needs one value per " + per + " (" +
                                      std::to_string(count) + "), got " + std::to_string(v.size() / arity));
                }
            };
            if (interp == "constant") {
                if (v.size() != arity) throw FormatError(where + ": " + line + ": " + at + ": constant " + name + " needs " + std::to_string(arity) + " number(s), got " + std::to_string(v.size()));
                for (std::size_t c = 0; c < arity; ++c) constant[c] = float(v[c]);
                return true;
            }
            if (interp == "uniform") { need(nC, "curve"); pv.interp = Interp::Uniform; }
            else if (interp == "vertex") { need(nP, "point"); pv.interp = Interp::Vertex; }
            else if (interp == "varying") { need(numVarying, linear ? "point" : "segment end"); pv.interp = Interp::Varying; }
            else throw FormatError(where + ": " + line + ": " + at + ": " + name + " has interpolation \"" + interp + "\"; expected constant, uniform, vertex or varying");
            pv.values.assign(v.begin(), v.end());
            return true;
        };
        StrandDefaults defaults = out.defaults;
        Primvar widths, colors, opacity;
        float opacityConstant = 1.f - defaults.transparency;
        const bool constantWidth = readPrimvar("widths", 1, widths, &defaults.thickness) && widths.values.empty();
        const bool constantColor = readPrimvar("primvars:displayColor", 3, colors, &defaults.color[0]) && colors.values.empty();
        const bool constantOpacity = readPrimvar("primvars:displayOpacity", 1, opacity, &opacityConstant) && opacity.values.empty();
        if (constantOpacity) defaults.transparency = 1.f - opacityConstant;
        // A per-vertex array of one value that writeUsda() wrote once (vdbhair_uniform_*): the
        // array again, so .hair -> .usda -> .hair keeps it.
        auto uniform = [&](const char* name) {
            const Property* f = find(name);
            return f && !f->value.words.empty() && f->value.words[0] == "true";
        };
        const bool uniformWidth = constantWidth && uniform("vdbhair_uniform_thickness");
        const bool displayWidth = constantWidth && uniform("vdbhair_display_width");
        const bool uniformColor = constantColor && uniform("vdbhair_uniform_color");
        const bool uniformOpacity = constantOpacity && uniform("vdbhair_uniform_transparency");
        auto asUniform = [&](Primvar& pv, const float* value) {  // one value for every curve
            pv.interp = Interp::Uniform;
            pv.values.resize(pv.arity * nC);
            for (std::size_t i = 0; i < nC; ++i) std::copy(value, value + pv.arity, pv.values.begin() + std::ptrdiff_t(pv.arity * i));
        };
        if (uniformWidth) asUniform(widths, &defaults.thickness);
        if (uniformColor) asUniform(colors, &defaults.color[0]);
        if (uniformOpacity) asUniform(opacity, &opacityConstant);
        // vdbhair's own record of the defaults (exact, and kept when the arrays are per vertex); a
        // constant primvar that is not such an array is what the file says for every vertex, and
        // wins (a width given to the writer).
        if (const Property* d = find("vdbhair_default_thickness"); d && d->value.numbers.size() == 1 && (!constantWidth || uniformWidth || displayWidth)) {
            defaults.thickness = float(d->value.numbers[0]);
        }
        if (const Property* d = find("vdbhair_default_transparency"); d && d->value.numbers.size() == 1) {
            // Exact where the constant opacity says the same (1 - t rounds in float).
            const float t = float(d->value.numbers[0]);
            if (!constantOpacity || uniformOpacity || 1.f - t == opacityConstant) defaults.transparency = t;
        }
        if (const Property* d = find("vdbhair_default_color"); d && d->value.numbers.size() == 3 && (!constantColor || uniformColor)) {
            defaults.color = Vec3f(float(d->value.numbers[0]), float(d->value.numbers[1]), float(d->value.numbers[2]));
        }
        // The prim's transform to the stage's space (its xformOps and its parents'); widths scale
        // with it.
        const xform::Matrix world = worldTransform(doc, prim.node, where, warn);
        const bool transformed = world != xform::kIdentity;
        const float widthScale = transformed ? float(xform::lengthScale(world)) : 1.f;
        if (transformed) defaults.thickness *= widthScale;
        if (first) out.defaults = defaults;
        first = false;

        // Strands, with the attributes where this prim has them (defaults elsewhere).
        StrandSet part;
        part.defaults = out.defaults;
        std::vector<Vec3f> controls, poly;
        std::size_t v0 = 0, vv0 = 0;
        for (std::size_t i = 0; i < nC; ++i) {
            const std::size_t cnt = std::size_t(n[i]);
            controls.clear();
            for (std::size_t k = v0; k < v0 + cnt; ++k) {
                const Vec3f q(static_cast<float>(p[3 * k]), static_cast<float>(p[3 * k + 1]), static_cast<float>(p[3 * k + 2]));
                checkFinite(q, k, where, at);
                controls.push_back(q);
                if (transformed) {
                    controls.back() = xform::transformPoint(world, q);
                    checkFinite(controls.back(), k, where, at + " after its transform");
                }
            }
            if (linear) {
                poly = controls;
                if (wrap == CurveWrap::Periodic && cnt >= 2) poly.push_back(controls.front());
            } else {
                poly.clear();
                const FreeFormCurve curve = cubicCurve(basis, wrap, controls.data(), cnt);
                if (std::string rule = flattenCurve(curve, opts.curveSamples, poly); !rule.empty()) {
                    throw FormatError(where + ": " + at + ": curve " + std::to_string(i) + " (cubic " + basisName + ", " + wrapName + "): " + rule);
                }
            }
            const std::size_t nv = linear ? cnt : cubicVaryingCount(basis, wrap, cnt);
            // A primvar at polyline point k: per curve, or between the values along the curve.
            auto valueAt = [&](const Primvar& pv, std::size_t k, std::size_t c) -> float {
                const std::size_t at0 = pv.interp == Interp::Uniform ? i : pv.interp == Interp::Vertex ? v0 : vv0;
                const std::size_t m = pv.interp == Interp::Uniform ? 1 : pv.interp == Interp::Vertex ? cnt : nv;
                if (m == 0) return 0.f;
                if (linear && m > 1) return pv.values[pv.arity * (at0 + (k < m ? k : 0)) + c];
                const CurvePosition pos = positionAlong(k, poly.size(), m);
                return (1.f - pos.f) * pv.values[pv.arity * (at0 + pos.i0) + c] + pos.f * pv.values[pv.arity * (at0 + pos.i1) + c];
            };
            if (filter.keep(strandIndex++, poly.size(), at + ", curve " + std::to_string(i))) {
                for (std::size_t k = 0; k < poly.size(); ++k) {
                    part.positions.push_back(poly[k]);
                    if (!widths.values.empty()) part.thickness.push_back(valueAt(widths, k, 0) * widthScale);
                    if (!colors.values.empty()) part.color.emplace_back(valueAt(colors, k, 0), valueAt(colors, k, 1), valueAt(colors, k, 2));
                    if (!opacity.values.empty()) part.transparency.push_back(1.f - valueAt(opacity, k, 0));
                }
                part.offsets.push_back(std::uint32_t(part.positions.size()));
            }
            v0 += cnt;
            vv0 += nv;
        }
        if (out.empty()) {
            out = std::move(part);
        } else {
            out.append(part);
        }
    }
    filter.finish();
    // The stage's space, carried (not applied): USD's fallbacks are centimetres and +Y up.
    out.metersPerUnit = doc.metersPerUnit > 0.0 ? doc.metersPerUnit : 0.01;
    out.upAxis = doc.upAxis == "Z" ? 'Z' : 'Y';
    return out;
}

float automaticUsdWidth(const StrandSet& strands)
{
    const BBox box = computeBBox(strands);
    const Vec3f d = box.max - box.min;
    const float diagonal = std::sqrt(d.x() * d.x() + d.y() * d.y() + d.z() * d.z());
    return diagonal > 0.f ? kAutomaticWidthPerDiagonal * diagonal : 1.f;
}

void writeUsda(const std::string& path, const StrandSet& strands, const UsdWriteOptions& opts)
{
    const std::string where = "writeUsda(" + path + ")";
    if (strands.empty()) throw ValueError(where + ": the hairstyle has no strands; there is nothing to write");
    if (!opts.upAxis.empty() && opts.upAxis != "Y" && opts.upAxis != "Z") throw ValueError(where + ": up axis '" + opts.upAxis + "' must be Y or Z (USD's choices)");
    const std::string upAxis = !opts.upAxis.empty() ? opts.upAxis : strands.upAxis == 'Z' ? "Z" : "Y";
    if (!(opts.metersPerUnit >= 0.0) || !std::isfinite(opts.metersPerUnit)) {
        throw ValueError(where + ": metersPerUnit " + std::to_string(opts.metersPerUnit) + " must be positive and finite (0: the strands' own, else 0.01)");
    }
    if (!(opts.width >= 0.0f) || !std::isfinite(opts.width)) {
        throw ValueError(where + ": width " + std::to_string(opts.width) + " must be positive and finite (0: automatic)");
    }
    const double metersPerUnit = opts.metersPerUnit > 0.0 ? opts.metersPerUnit : strands.metersPerUnit > 0.0 ? strands.metersPerUnit : 0.01;
    const std::size_t nV = strands.numVertices(), nS = strands.numStrands();
    std::string out;
    reserveHugePages(out, 64 * nV + 8 * nS + 1024);
    char buf[64];
    auto num = [&](double v, bool isFloat = true) {
        const auto res = isFloat ? std::to_chars(buf, buf + sizeof buf, float(v)) : std::to_chars(buf, buf + sizeof buf, v);
        out.append(buf, res.ptr);
    };
    auto vec3 = [&](const Vec3f& v) {
        out += '(';
        num(v.x()); out += ", "; num(v.y()); out += ", "; num(v.z());
        out += ')';
    };
    out += "#usda 1.0\n(\n    defaultPrim = \"hair\"\n    doc = \"";
    out += creatorString();
    out += ": " + std::to_string(nS) + " strands, " + std::to_string(nV) + " vertices, root to tip\"\n    metersPerUnit = ";
    num(metersPerUnit, false);
    out += "\n    upAxis = \"" + upAxis + "\"\n)\n\n";
    out += "def BasisCurves \"hair\"\n{\n";
    out += "    uniform token type = \"linear\"\n";
    out += "    uniform token wrap = \"nonperiodic\"\n";
    out += "    int[] curveVertexCounts = [";
    for (std::size_t i = 0; i < nS; ++i) {
        if (i) out += ", ";
        out += std::to_string(strands.size(i));
    }
    out += "]\n    point3f[] points = [";
    for (std::size_t v = 0; v < nV; ++v) {
        if (v) out += ", ";
        vec3(strands.positions[v]);
    }
    out += "]\n";
    // Widths, colour and opacity: per vertex where the set has them and they vary; one value with
    // "constant" interpolation where they do not (a .hair file's colour array of one colour, the
    // defaults where the set has no array).
    auto uniformValue = [](const auto& values) {
        return std::all_of(values.begin(), values.end(), [&](const auto& v) { return v == values.front(); });
    };
    std::string uniformFlags;  // vdbhair_uniform_*: which constants stand for a per-vertex array
    auto primvar = [&](const char* decl, const auto& values, const auto& constant, auto write, const char* flag) {
        const bool constantValue = values.empty() || uniformValue(values);
        if (!values.empty() && constantValue) uniformFlags += std::string("    custom bool vdbhair_uniform_") + flag + " = true\n";
        out += std::string("    ") + decl + " = [";
        if (constantValue) write(values.empty() ? constant : values.front());
        else for (std::size_t v = 0; v < values.size(); ++v) { if (v) out += ", "; write(values[v]); }
        out += std::string("] (\n        interpolation = \"") + (constantValue ? "constant" : "vertex") + "\"\n    )\n";
    };
    auto writeFloat = [&](float x) { num(x); };
    auto writeVec3 = [&](const Vec3f& v) { vec3(v); };
    // Curves without thickness: --width, else the file's declared default, else automatic (a
    // thousandth of the bounding box's diagonal; writing 1 drew hair in metres as a blob).
    float constantWidth = strands.defaults.thickness;
    if (strands.thickness.empty()) {
        if (opts.width > 0.f) constantWidth = opts.width;
        else if (strands.defaults.thickness == StrandDefaults{}.thickness) constantWidth = automaticUsdWidth(strands);
    }
    // A width chosen for display (not the strands' thickness): vdbhair reads the defaults back
    // exactly, other tools draw the width.
    if (constantWidth != strands.defaults.thickness) uniformFlags += "    custom bool vdbhair_display_width = true\n";
    primvar("float[] widths", strands.thickness, constantWidth, writeFloat, "thickness");
    primvar("color3f[] primvars:displayColor", strands.color, strands.defaults.color, writeVec3, "color");
    std::vector<float> opacity(strands.transparency.size());
    for (std::size_t v = 0; v < opacity.size(); ++v) opacity[v] = 1.f - strands.transparency[v];
    primvar("float[] primvars:displayOpacity", opacity, 1.f - strands.defaults.transparency, writeFloat, "transparency");
    // The defaults themselves (cyHair's header), exactly, whether or not the arrays are per vertex.
    out += "    custom float vdbhair_default_thickness = ";
    num(strands.defaults.thickness);
    out += "\n    custom float vdbhair_default_transparency = ";
    num(strands.defaults.transparency);
    out += "\n    custom color3f vdbhair_default_color = ";
    vec3(strands.defaults.color);
    out += "\n" + uniformFlags;
    const BBox box = computeBBox(strands);
    out += "    float3[] extent = [";
    vec3(box.min);
    out += ", ";
    vec3(box.max);
    out += "]\n}\n";
    writeFileAtomic(path, out, where);
}

} // namespace vdbhair
