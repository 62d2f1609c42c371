#pragma once
// Internal to sdfkit_io: a forward-only cursor over a text file held in memory, for the OFF,
// OBJ and ASCII PLY readers. Numbers are parsed with std::from_chars (no locale, no iostream),
// and errors name the file and the line.

#include "readers.hpp"

#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>

namespace sdfkit::io::detail {

class TextCursor {
public:
  TextCursor(std::string_view data, const std::string& path, std::size_t start = 0)
      : data_(data), path_(path), pos_(start) {}

  bool at_end() const { return pos_ >= data_.size(); }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }

  // Skips spaces, tabs and carriage returns, staying on the current line.
  void skip_inline_space() {
    while (pos_ < data_.size() && (data_[pos_] == ' ' || data_[pos_] == '\t' ||
                                   data_[pos_] == '\r' || data_[pos_] == '\f' ||
                                   data_[pos_] == '\v'))
      ++pos_;
  }

  // Skips whitespace, line breaks and (when `comments`) '#' comments up to the next token.
  void skip_blank(bool comments = true) {
    while (pos_ < data_.size()) {
      const char ch = data_[pos_];
      if (ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '\f' || ch == '\v') {
        ++pos_;
      } else if (comments && ch == '#') {
        next_line();
      } else {
        break;
      }
    }
  }

  // True at a line break, a '#' comment or the end of the data (after inline space).
  bool at_line_end() {
    skip_inline_space();
    return pos_ >= data_.size() || data_[pos_] == '\n' || data_[pos_] == '#';
  }

  // Moves past the next line break (or to the end).
  void next_line() {
    const std::size_t nl = data_.find('\n', pos_);
    pos_ = nl == std::string_view::npos ? data_.size() : nl + 1;
  }

  // The next run of non-whitespace characters on this line (empty at the line's end).
  std::string_view word() {
    skip_inline_space();
    const std::size_t begin = pos_;
    while (pos_ < data_.size() && !is_space(data_[pos_])) ++pos_;
    return data_.substr(begin, pos_ - begin);
  }

  // The next word without consuming it.
  std::string_view peek_word() {
    const std::size_t saved = pos_;
    const std::string_view w = word();
    pos_ = saved;
    return w;
  }

  // Parse a number on the current line; false (cursor left before the token) when the next
  // token is not a number or the line has ended. A number must end at whitespace, a '#', the
  // end of the data or (try_int with `allow_slash`, for OBJ corners) a '/'.
  bool try_float(float& out) {
    skip_inline_space();
    std::size_t p = pos_;
    if (p < data_.size() && data_[p] == '+') ++p;
    const char* first = data_.data() + p;
    const char* last = data_.data() + data_.size();
    const auto [ptr, ec] = std::from_chars(first, last, out);
    if (ec == std::errc::result_out_of_range) {
      // Overflowing literals such as 1e999 become +-Inf, rejected later as non-finite;
      // underflow becomes 0.
      return false;
    }
    if (ec != std::errc() || !ends_token(ptr, false)) return false;
    pos_ = static_cast<std::size_t>(ptr - data_.data());
    return true;
  }

  bool try_int(std::int64_t& out, bool allow_slash = false) {
    skip_inline_space();
    std::size_t p = pos_;
    if (p < data_.size() && data_[p] == '+') ++p;
    const char* first = data_.data() + p;
    const char* last = data_.data() + data_.size();
    const auto [ptr, ec] = std::from_chars(first, last, out);
    if (ec != std::errc() || !ends_token(ptr, allow_slash)) return false;
    pos_ = static_cast<std::size_t>(ptr - data_.data());
    return true;
  }

  // Skips a run of characters that are not whitespace (the rest of a token).
  void skip_token() {
    while (pos_ < data_.size() && !is_space(data_[pos_])) ++pos_;
  }

  // Throws InputError "<path>: line N: expected <what>, found '<token>'" (or "unexpected end of
  // file: expected <what>").
  [[noreturn]] void expected(const std::string& what) {
    skip_inline_space();
    if (at_end()) fail(path_, "unexpected end of file: expected " + what);
    if (data_[pos_] == '\n')
      error("expected " + what + ", found the end of the line");
    std::size_t end = pos_;
    while (end < data_.size() && !is_space(data_[end]) && end - pos_ < 24) ++end;
    error("expected " + what + ", found '" + printable(data_.substr(pos_, end - pos_)) + "'");
  }

  // Throws InputError "<path>: line N: <problem>".
  [[noreturn]] void error(const std::string& problem) const {
    fail(path_, "line " + std::to_string(line()) + ": " + problem);
  }

  // 1-based line number of the cursor.
  std::size_t line() const {
    std::size_t n = 1;
    const std::size_t end = pos_ < data_.size() ? pos_ : data_.size();
    for (std::size_t i = 0; i < end; ++i) n += data_[i] == '\n';
    return n;
  }

  static bool is_space(char ch) {
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '\f' || ch == '\v';
  }

  // Replaces control and non-ASCII bytes so an error message stays on one printable line.
  static std::string printable(std::string_view s) {
    std::string out;
    for (const char ch : s) {
      const auto u = static_cast<unsigned char>(ch);
      out += (u >= 0x20 && u < 0x7f) ? ch : '?';
    }
    return out;
  }

private:
  bool ends_token(const char* ptr, bool allow_slash) const {
    if (ptr == data_.data() + data_.size()) return true;
    return is_space(*ptr) || *ptr == '#' || (allow_slash && *ptr == '/');
  }

  std::string_view data_;
  const std::string& path_;
  std::size_t pos_ = 0;
};

}  // namespace sdfkit::io::detail
