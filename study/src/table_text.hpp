#pragma once
// Large text files of the study, fast (private to study/src): rows formatted in parallel chunks by
// worker threads into their own buffers, written in order by the calling thread in large writes
// while the next chunks are formatted. Numbers as their shortest round-trip text (number_text.hpp).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "impactdeck/study/sweep.hpp"

namespace impactdeck::study::detail {

/// Appends the text of rows [begin, end) to `out` (one worker's chunk; called concurrently for
/// different chunks: it must only read shared data).
using RowsText = std::function<void(std::size_t begin, std::size_t end, std::string& out)>;

struct RowWriteOptions {
  unsigned threads = 0;         ///< formatting workers; 0: all cores
  std::size_t chunk_rows = 8192;
  /// (rows written so far, rows in total), from the calling thread, about ten times a second and
  /// once at the end.
  ProgressFn progress;
};

/// Writes the `rows` rows that `text` formats to `o`, in row order. The text is the same whatever
/// the thread count. Exceptions of `text` (the lowest chunk's) and write failures propagate.
void write_rows(std::ostream& o, std::size_t rows, const RowsText& text, const RowWriteOptions& options = {});

/// A CSV table defined column by column: numbers (shortest round-trip text), integers and short
/// words (no comma, quote or line break: the writer refuses them).
class CsvTable {
 public:
  void number(std::string name, std::function<double(std::size_t row)> get);
  void integer(std::string name, std::function<std::uint64_t(std::size_t row)> get);
  void text(std::string name, std::function<std::string_view(std::size_t row)> get);
  std::size_t columns() const { return columns_.size(); }
  /// "name1,name2,...\n"
  std::string header() const;
  /// RowsText of the table; `what` names the writer in an internal error (non-finite number).
  RowsText rows(const char* what) const;

 private:
  struct Column {
    std::string name;
    std::function<double(std::size_t)> number;
    std::function<std::uint64_t(std::size_t)> integer;
    std::function<std::string_view(std::size_t)> text;
  };
  std::vector<Column> columns_;
};

}  // namespace impactdeck::study::detail
