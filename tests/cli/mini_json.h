// A strict little JSON parser for the tests (RFC 8259: no NaN, no trailing commas, no
// comments, valid UTF-8, escapes checked). Written for checking the tool's reports, not
// for speed. Header-only; everything is inline.
#ifndef STRATMESH_TESTS_MINI_JSON_H
#define STRATMESH_TESTS_MINI_JSON_H

#include <cstddef>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

namespace mini_json {

struct Value {
    enum Kind { null, boolean, number, string, array, object };
    Kind kind = null;
    bool flag = false;
    double num = 0;
    std::string text;
    std::vector<Value> items;                           // array
    std::vector<std::pair<std::string, Value>> members; // object, in order

    const Value* member(const std::string& key) const {
        for (const auto& m : members)
            if (m.first == key) return &m.second;
        return nullptr;
    }

    // The array item at a decimal index, or nullptr.
    const Value* item(const std::string& index) const {
        if (kind != array || index.empty() ||
            index.find_first_not_of("0123456789") != std::string::npos)
            return nullptr;
        size_t i = std::strtoul(index.c_str(), nullptr, 10);
        return i < items.size() ? &items[i] : nullptr;
    }

    // Follows "a.b.2.c" through nested objects (keys) and arrays (indices); nullptr if
    // any step is missing.
    const Value* at(const std::string& dotted) const {
        const Value* v = this;
        size_t start = 0;
        while (v && start <= dotted.size()) {
            size_t dot = dotted.find('.', start);
            std::string key =
                dotted.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
            v = v->kind == object ? v->member(key) : v->item(key);
            if (dot == std::string::npos) break;
            start = dot + 1;
        }
        return v;
    }
};

class Parser {
public:
    explicit Parser(const std::string& text) : s_(text) {}

    bool parse(Value& out, std::string& error) {
        bool ok = value(out, 0);
        skip_space();
        if (ok && pos_ != s_.size()) ok = fail("text after the value");
        if (!ok) error = "byte " + std::to_string(pos_) + ": " + error_;
        return ok;
    }

private:
    bool fail(const char* why) {
        if (error_.empty()) error_ = why;
        return false;
    }

    void skip_space() {
        while (pos_ < s_.size() &&
               (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r'))
            ++pos_;
    }

    bool eat(char c) {
        skip_space();
        if (pos_ < s_.size() && s_[pos_] == c) {
            ++pos_;
            return true;
        }
        return false;
    }

    bool word(const char* w) {
        std::string expected(w);
        if (s_.compare(pos_, expected.size(), expected) != 0) return fail("unknown literal");
        pos_ += expected.size();
        return true;
    }

    bool value(Value& v, int depth) {
        if (depth > 64) return fail("nested too deeply");
        skip_space();
        if (pos_ >= s_.size()) return fail("unexpected end");
        char c = s_[pos_];
        if (c == '{') return object(v, depth);
        if (c == '[') return array(v, depth);
        if (c == '"') {
            v.kind = Value::string;
            return string_literal(v.text);
        }
        if (c == 't' || c == 'f') {
            v.kind = Value::boolean;
            v.flag = c == 't';
            return word(v.flag ? "true" : "false");
        }
        if (c == 'n') {
            v.kind = Value::null;
            return word("null");
        }
        return number(v);
    }

    bool object(Value& v, int depth) {
        v.kind = Value::object;
        ++pos_;
        if (eat('}')) return true;
        do {
            std::pair<std::string, Value> m;
            skip_space();
            if (pos_ >= s_.size() || s_[pos_] != '"') return fail("expected a key");
            if (!string_literal(m.first)) return false;
            if (!eat(':')) return fail("expected ':'");
            if (!value(m.second, depth + 1)) return false;
            v.members.push_back(std::move(m));
        } while (eat(','));
        return eat('}') || fail("expected ',' or '}'");
    }

    bool array(Value& v, int depth) {
        v.kind = Value::array;
        ++pos_;
        if (eat(']')) return true;
        do {
            Value item;
            if (!value(item, depth + 1)) return false;
            v.items.push_back(std::move(item));
        } while (eat(','));
        return eat(']') || fail("expected ',' or ']'");
    }

    bool digits() {
        size_t start = pos_;
        while (pos_ < s_.size() && s_[pos_] >= '0' && s_[pos_] <= '9') ++pos_;
        return pos_ > start;
    }

    bool number(Value& v) {
        size_t start = pos_;
        if (pos_ < s_.size() && s_[pos_] == '-') ++pos_;
        if (pos_ < s_.size() && s_[pos_] == '0')
            ++pos_;
        else if (!digits())
            return fail("not a value");
        if (pos_ < s_.size() && s_[pos_] == '.') {
            ++pos_;
            if (!digits()) return fail("bad fraction");
        }
        if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
            ++pos_;
            if (pos_ < s_.size() && (s_[pos_] == '+' || s_[pos_] == '-')) ++pos_;
            if (!digits()) return fail("bad exponent");
        }
        v.kind = Value::number;
        v.num = std::strtod(s_.substr(start, pos_ - start).c_str(), nullptr);
        return true;
    }

    bool hex4(unsigned& code) {
        code = 0;
        for (int i = 0; i < 4; ++i, ++pos_) {
            if (pos_ >= s_.size()) return fail("short \\u escape");
            char c = s_[pos_];
            unsigned d = c >= '0' && c <= '9'   ? unsigned(c - '0')
                         : c >= 'a' && c <= 'f' ? unsigned(c - 'a' + 10)
                         : c >= 'A' && c <= 'F' ? unsigned(c - 'A' + 10)
                                                : 16u;
            if (d == 16) return fail("bad \\u escape");
            code = code * 16 + d;
        }
        return true;
    }

    bool escape(std::string& out) {
        if (pos_ >= s_.size()) return fail("unterminated escape");
        char c = s_[pos_++];
        const std::string simple = "\"\\/bfnrt", meaning = "\"\\/\b\f\n\r\t";
        size_t k = simple.find(c);
        if (k != std::string::npos) {
            out += meaning[k];
            return true;
        }
        unsigned code = 0;
        if (c != 'u' || !hex4(code)) return fail("bad escape");
        out += '?'; // the code point itself does not matter to the tests
        return true;
    }

    // Length of a valid UTF-8 sequence at pos_, 0 if invalid.
    size_t utf8_length() const {
        unsigned char c = static_cast<unsigned char>(s_[pos_]);
        size_t n = c < 0x80                 ? 1
                   : c >= 0xc2 && c <= 0xdf ? 2
                   : c >= 0xe0 && c <= 0xef ? 3
                   : c >= 0xf0 && c <= 0xf4 ? 4
                                            : 0;
        if (n == 0 || pos_ + n > s_.size()) return 0;
        for (size_t i = 1; i < n; ++i)
            if ((static_cast<unsigned char>(s_[pos_ + i]) & 0xc0) != 0x80) return 0;
        return n;
    }

    bool string_literal(std::string& out) {
        ++pos_; // the opening quote
        while (pos_ < s_.size()) {
            unsigned char c = static_cast<unsigned char>(s_[pos_]);
            if (c == '"') {
                ++pos_;
                return true;
            }
            if (c < 0x20) return fail("control character in a string");
            if (c == '\\') {
                ++pos_;
                if (!escape(out)) return false;
                continue;
            }
            size_t n = utf8_length();
            if (n == 0) return fail("invalid UTF-8");
            out.append(s_, pos_, n);
            pos_ += n;
        }
        return fail("unterminated string");
    }

    const std::string& s_;
    size_t pos_ = 0;
    std::string error_;
};

inline bool parse(const std::string& text, Value& out, std::string& error) {
    return Parser(text).parse(out, error);
}

} // namespace mini_json

#endif
