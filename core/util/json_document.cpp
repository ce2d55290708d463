#include "core/util/json_document.hpp"

#include <vector>
#include "core/util/error.hpp"
#include "core/util/memory_budget.hpp"

namespace gilab {

using json = nlohmann::json;

namespace {

// A parsed value takes about this many bytes per byte of JSON text (a 16-byte value per
// short token, map nodes for keys, vector growth).
constexpr uint64_t kDocumentBytesPerTextByte = 16;
// Deeper documents are not data anyone writes by hand or exports; recursive consumers
// (tinygltf's extras) would overflow the stack on them.
constexpr size_t kMaxDepth = 256;

// Builds the document like nlohmann's own DOM parser and remembers where it is, so an
// error can name the JSON pointer of the value being read.
class LocatingParser {
public:
    json root;
    size_t error_position = 0;
    std::string error_message;  // empty: no error

    bool null() { return add(json(nullptr)); }
    bool boolean(bool v) { return add(json(v)); }
    bool number_integer(json::number_integer_t v) { return add(json(v)); }
    bool number_unsigned(json::number_unsigned_t v) { return add(json(v)); }
    bool number_float(json::number_float_t v, const json::string_t&) { return add(json(v)); }
    bool string(json::string_t& v) { return add(json(std::move(v))); }
    bool binary(json::binary_t& v) { return add(json(json::binary_t(std::move(v)))); }
    bool start_object(size_t) { return open(json::object()); }
    bool start_array(size_t) { return open(json::array()); }
    bool end_object() { return close(); }
    bool end_array() { return close(); }
    bool key(json::string_t& k) {
        frames_.back().key = k;
        frames_.back().has_key = true;
        return true;
    }
    bool parse_error(size_t position, const std::string& token, const nlohmann::detail::exception& e) {
        error_position = position;
        if (e.id == 406)  // out_of_range.406: number overflow
            error_message = pointer() + ": number " + token + " is out of range (beyond what a double can hold)";
        else
            error_message = prefix() + "JSON syntax error: " + strip_id(e.what());
        return false;
    }

    // The pointer of the value being read, e.g. "/meshes/0/scale" ("/" at the top).
    std::string pointer() const {
        std::string p;
        for (size_t i = 0; i < frames_.size(); ++i) {
            const Frame& f = frames_[i];
            const bool top = i + 1 == frames_.size();
            if (f.container->is_array()) {
                const size_t n = f.container->size();
                p += '/';
                p += std::to_string(top ? n : n - 1);
            } else if (!top || f.has_key) {
                p += '/';
                p += json_pointer_token(f.key);
            }
        }
        if (p.size() > 120) p = p.substr(0, 100) + "/...";  // a pathologically deep path
        return p.empty() ? "/" : p;
    }

private:
    struct Frame {
        json* container;
        std::string key;
        bool has_key = false;
    };
    std::vector<Frame> frames_;

    std::string prefix() const {
        const std::string p = pointer();
        return p == "/" ? std::string() : p + ": ";
    }

    static std::string strip_id(const std::string& message) {
        const size_t colon = message.find(": ");
        if (colon != std::string::npos && message.rfind("[json.exception", 0) == 0) return message.substr(colon + 2);
        return message;
    }

    json* place(json&& v) {
        if (frames_.empty()) {
            root = std::move(v);
            return &root;
        }
        Frame& f = frames_.back();
        if (f.container->is_array()) {
            f.container->push_back(std::move(v));
            return &f.container->back();
        }
        f.has_key = false;
        json& slot = (*f.container)[f.key];
        slot = std::move(v);
        return &slot;
    }
    bool add(json&& v) {
        place(std::move(v));
        return true;
    }
    bool open(json&& container) {
        if (frames_.size() >= kMaxDepth) {
            error_message = pointer() + ": nested deeper than " + std::to_string(kMaxDepth) + " levels";
            return false;
        }
        // Only the innermost container grows, so pointers to the outer ones stay valid.
        json* c = place(std::move(container));
        frames_.push_back({c, {}, false});
        return true;
    }
    bool close() {
        frames_.pop_back();
        return true;
    }
};

}  // namespace

std::string json_pointer_token(const std::string& key) {
    std::string out;
    for (char c : key) {
        if (c == '~') out += "~0";
        else if (c == '/') out += "~1";
        else out += c;
    }
    return out;
}

json parse_json_document(const std::string& text, const std::string& file, const std::string& kind) {
    MemoryBudget::check(MemoryBudget::times(text.size(), kDocumentBytesPerTextByte), "parsing its JSON", file);
    LocatingParser parser;
    const bool ok = json::sax_parse(text, &parser);
    if (ok && parser.error_message.empty()) return std::move(parser.root);
    if (parser.error_message.empty()) parser.error_message = "JSON syntax error";
    parser.error_message = kind + parser.error_message;
    if (parser.error_position == 0) throw Error(file, parser.error_message);  // not at a known byte
    // Line and column of the byte where the parser stopped.
    size_t line = 1, column = 1;
    for (size_t i = 0; i + 1 < parser.error_position && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    throw Error(file + ":" + std::to_string(line) + ":" + std::to_string(column), parser.error_message);
}

}  // namespace gilab
