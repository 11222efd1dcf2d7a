#include "UsdText.h"

#include <vdbhair/Exceptions.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>

namespace vdbhair {
namespace usd {

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

void checkNesting(const UsdLexer& lex, int depth, const char* what)
{
    if (depth > kMaxNesting) {
        lex.fail(std::string(what) + " nested more than " + std::to_string(kMaxNesting) + " deep; USD text here nests at most " +
                 std::to_string(kMaxNesting) + " levels");
    }
}

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

} // namespace

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

} // namespace usd
} // namespace vdbhair
