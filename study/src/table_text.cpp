#include "table_text.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

#include "impactdeck/common/error.hpp"
#include "number_text.hpp"
#include "parallel.hpp"

namespace impactdeck::study::detail {

void write_rows(std::ostream& o, std::size_t rows, const RowsText& text, const RowWriteOptions& opt) {
  using Clock = std::chrono::steady_clock;
  const std::size_t chunk = std::max<std::size_t>(1, opt.chunk_rows);
  const std::size_t chunks = (rows + chunk - 1) / chunk;
  const unsigned workers =
      static_cast<unsigned>(std::min<std::size_t>(resolve_threads(opt.threads), std::max<std::size_t>(1, chunks)));
  auto range = [&](std::size_t c) { return std::make_pair(c * chunk, std::min(rows, (c + 1) * chunk)); };
  auto last_report = Clock::now();
  auto report = [&](std::size_t done, bool force) {
    if (!opt.progress) return;
    const auto now = Clock::now();
    if (force || now - last_report > std::chrono::milliseconds(100)) {
      opt.progress(done, rows);
      last_report = now;
    }
  };
  auto put = [&](const std::string& s) {
    o.write(s.data(), static_cast<std::streamsize>(s.size()));
    // write_file_atomically turns this into the file's own "write failed: REASON" (exit 3).
    if (!o) throw Error(ExitCode::internal_error, "write failed");
  };

  if (workers <= 1) {
    std::string buf;
    for (std::size_t c = 0; c < chunks; ++c) {
      const auto [b, e] = range(c);
      buf.clear();
      text(b, e, buf);
      put(buf);
      report(e, false);
    }
    report(rows, true);
    return;
  }

  // A ring of 2 w + 2 buffers: chunk c is formatted into slot c % R, and only once chunk c - R has
  // been written, so at most R chunks are held in memory.
  const std::size_t ring = 2 * static_cast<std::size_t>(workers) + 2;
  struct Slot {
    std::string text;
    bool ready = false;
  };
  std::vector<Slot> slots(ring);
  std::mutex m;
  std::condition_variable to_workers, to_writer;
  std::size_t next = 0, written = 0;
  bool stop = false;
  FirstError first_error;

  auto work = [&] {
    for (;;) {
      std::size_t c;
      {
        std::unique_lock<std::mutex> lock(m);
        to_workers.wait(lock, [&] { return stop || next >= chunks || next < written + ring; });
        if (stop || next >= chunks) return;
        c = next++;
      }
      Slot& slot = slots[c % ring];  // free: chunk c - ring is written, and c is this worker's alone
      slot.text.clear();
      try {
        const auto [b, e] = range(c);
        text(b, e, slot.text);
      } catch (...) {
        std::lock_guard<std::mutex> lock(m);
        first_error.keep(c, std::current_exception());
        stop = true;
        to_writer.notify_all();
        to_workers.notify_all();
        return;
      }
      std::lock_guard<std::mutex> lock(m);
      slot.ready = true;
      to_writer.notify_all();
    }
  };
  std::vector<std::thread> pool;
  struct Stopper {  // on any exit: wake and join the workers
    std::mutex& m;
    bool& stop;
    std::condition_variable& cv;
    std::vector<std::thread>& pool;
    ~Stopper() {
      {
        std::lock_guard<std::mutex> lock(m);
        stop = true;
      }
      cv.notify_all();
      for (auto& t : pool)
        if (t.joinable()) t.join();
    }
  } stopper{m, stop, to_workers, pool};
  for (unsigned t = 0; t < workers; ++t) pool.emplace_back(work);

  for (std::size_t c = 0; c < chunks; ++c) {
    Slot& slot = slots[c % ring];
    {
      std::unique_lock<std::mutex> lock(m);
      while (!stop && !slot.ready) {
        to_writer.wait_for(lock, std::chrono::milliseconds(100));
        lock.unlock();
        report(c * chunk, false);
        lock.lock();
      }
      if (!slot.ready) break;  // a worker failed
    }
    put(slot.text);  // outside the lock: the workers format on
    {
      std::lock_guard<std::mutex> lock(m);
      slot.ready = false;
      written = c + 1;
    }
    to_workers.notify_all();
    report(range(c).second, false);
  }
  {
    std::lock_guard<std::mutex> lock(m);
    if (first_error.error) std::rethrow_exception(first_error.error);
  }
  report(rows, true);
}

void CsvTable::number(std::string name, std::function<double(std::size_t)> get) {
  columns_.push_back({std::move(name), std::move(get), nullptr, nullptr});
}
void CsvTable::integer(std::string name, std::function<std::uint64_t(std::size_t)> get) {
  columns_.push_back({std::move(name), nullptr, std::move(get), nullptr});
}
void CsvTable::text(std::string name, std::function<std::string_view(std::size_t)> get) {
  columns_.push_back({std::move(name), nullptr, nullptr, std::move(get)});
}

std::string CsvTable::header() const {
  std::string h;
  for (const Column& c : columns_) h += (h.empty() ? "" : ",") + c.name;
  return h + "\n";
}

RowsText CsvTable::rows(const char* what) const {
  return [this, what](std::size_t begin, std::size_t end, std::string& out) {
    // Each row is formatted in place: the string grows by a bound of the row's length (numbers at
    // most kShortestMax characters), the text is written through a pointer, then trimmed.
    std::vector<std::string_view> texts(columns_.size());
    for (std::size_t i = begin; i < end; ++i) {
      std::size_t bound = columns_.size();  // separators and the line end
      for (std::size_t k = 0; k < columns_.size(); ++k) {
        const Column& c = columns_[k];
        if (c.text) {
          texts[k] = c.text(i);
          if (texts[k].find_first_of(",\"\r\n") != std::string_view::npos) {
            throw Error(ExitCode::internal_error, std::string(what) + ": column " + c.name + " holds '" +
                                                      std::string(texts[k]) + "' (no comma, quote or line break)");
          }
          bound += texts[k].size();
        } else {
          bound += kShortestMax;
        }
      }
      const std::size_t start = out.size();
      out.resize(start + bound);
      char* p = &out[start];
      for (std::size_t k = 0; k < columns_.size(); ++k) {
        if (k > 0) *p++ = ',';
        const Column& c = columns_[k];
        if (c.number) {
          p = put_shortest(p, c.number(i), what);
        } else if (c.integer) {
          p = std::to_chars(p, p + kShortestMax, c.integer(i)).ptr;
        } else {
          p = std::copy(texts[k].begin(), texts[k].end(), p);
        }
      }
      *p++ = '\n';
      out.resize(static_cast<std::size_t>(p - out.data()));
    }
  };
}

}  // namespace impactdeck::study::detail
