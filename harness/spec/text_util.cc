#include "harness/spec/text_util.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

namespace adse::spec {

int EditDistance(std::string_view a, std::string_view b) {
  // Optimal string alignment: like Levenshtein, but a swap of two adjacent
  // letters ("gaol" for "goal") counts as one edit. Inputs are short keys.
  auto lower = [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  };
  const size_t n = a.size(), m = b.size();
  std::vector<int> d((n + 1) * (m + 1));
  auto at = [&](size_t i, size_t j) -> int& { return d[i * (m + 1) + j]; };
  for (size_t i = 0; i <= n; ++i) at(i, 0) = static_cast<int>(i);
  for (size_t j = 0; j <= m; ++j) at(0, j) = static_cast<int>(j);
  for (size_t i = 1; i <= n; ++i) {
    for (size_t j = 1; j <= m; ++j) {
      const int cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      at(i, j) = std::min(
          {at(i - 1, j) + 1, at(i, j - 1) + 1, at(i - 1, j - 1) + cost});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) &&
          lower(a[i - 2]) == lower(b[j - 1])) {
        at(i, j) = std::min(at(i, j), at(i - 2, j - 2) + 1);
      }
    }
  }
  return at(n, m);
}

std::string DidYouMean(std::string_view word,
                       const std::vector<std::string>& candidates) {
  // Long garbage must not cost much: keys are short, so skip the work.
  if (word.empty() || word.size() > 64) return "";
  const std::string* best = nullptr;
  int best_score = 0;
  for (const std::string& candidate : candidates) {
    if (candidate == word) continue;
    int score = EditDistance(word, candidate);
    // Short words tolerate one edit, longer ones two, so that unrelated
    // short words are not suggested.
    const int limit = std::min<int>(
        2, std::max<int>(1, static_cast<int>(candidate.size()) / 3));
    // A truncated name ("lidar" for "lidar_hz") is a likely slip too.
    const std::string_view shorter =
        word.size() < candidate.size() ? word : std::string_view(candidate);
    const std::string_view longer =
        word.size() < candidate.size() ? std::string_view(candidate) : word;
    const bool prefix =
        shorter.size() >= 3 && longer.substr(0, shorter.size()) == shorter;
    if (prefix) score = std::min(score, limit);
    if (score > limit) continue;
    if (best == nullptr || score < best_score) {
      best = &candidate;
      best_score = score;
    }
  }
  return best ? " (did you mean '" + *best + "'?)" : "";
}

bool ParseNumber(std::string_view text, double* value) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty() || text.front() == '+' || text.front() == ' ') return false;
  double parsed = 0.0;
  const auto [end, ec] =
      std::from_chars(text.data(), text.data() + text.size(), parsed);
  if (ec != std::errc() || end != text.data() + text.size()) return false;
  if (!std::isfinite(parsed)) return false;
  *value = parsed;
  return true;
}

std::string FormatNumber(double value) {
  if (value == 0.0) return "0";  // no "-0"
  return fmt::format("{}", value);
}

std::string Counted(size_t count, std::string_view noun) {
  return fmt::format("{} {}{}", count, noun, count == 1 ? "" : "s");
}

std::string JoinList(const std::vector<std::string>& items,
                     std::string_view quote) {
  std::string out;
  for (const std::string& item : items) {
    if (!out.empty()) out += ", ";
    out += quote;
    out += item;
    out += quote;
  }
  return out;
}

}  // namespace adse::spec
