#pragma once
// An array of doubles of any length in bounded memory (issue 32: a ballbar run of an hour at
// 10 kHz is 36 M samples, and the circle analysis makes several passes over them and over
// per-sample values derived from them). At most `pages_held` pages of `page_values` values are
// held; the others live in an unlinked temporary file (in $TMPDIR, else /tmp) that the system
// removes when the array goes, even after a crash. An array that never outgrows its held pages
// never opens a file: a short run is an ordinary array in memory.
//
// Reading and writing go through the held pages, the least recently used one written back when
// another is needed, so sequential passes (forwards or backwards, a few at once) and small
// windows cost one page read per page; random access costs a page read per access. The values
// read are the values written, bit for bit. Not thread-safe (a const read may load a page).
// The analysis library's one use of a file: nothing else in it does I/O.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace cal {

struct PageOptions {
  std::size_t page_values = 65536;  // 512 KiB a page (a power of two)
  std::size_t pages_held = 4;       // 2 MiB an array at most
};

class PagedDoubles {
 public:
  PagedDoubles() : PagedDoubles(0, PageOptions{}) {}
  // `size` zeros.
  explicit PagedDoubles(std::size_t size, PageOptions options = {});
  PagedDoubles(PagedDoubles&&) noexcept;
  PagedDoubles& operator=(PagedDoubles&&) noexcept;
  PagedDoubles(const PagedDoubles&) = delete;  // a copy is a pass over the values: copy()
  PagedDoubles& operator=(const PagedDoubles&) = delete;
  ~PagedDoubles();

  PagedDoubles copy() const;

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const PageOptions& options() const { return options_; }

  double operator[](std::size_t i) const {
    if ((i >> shift_) != hot_page_) hot(i >> shift_, false);
    return hot_values_[i & mask_];
  }
  void set(std::size_t i, double v) {
    if ((i >> shift_) != hot_page_ || !hot_dirty_) hot(i >> shift_, true);
    hot_values_[i & mask_] = v;
  }
  void push_back(double v) { set(size_++, v); }

  // Pages written to a file by any PagedDoubles so far (a test's evidence that it paged).
  static std::uint64_t pages_spilled();

 private:
  struct Slot {
    std::size_t page = SIZE_MAX;
    bool dirty = false;
    std::uint64_t used = 0;  // the time of its last use, for the least recently used
    std::unique_ptr<double[]> values;
  };
  void hot(std::size_t page, bool for_write) const;
  void write_back(Slot& s) const;
  void open_file() const;

  PageOptions options_;
  std::size_t shift_ = 16, mask_ = 65535, size_ = 0;
  mutable std::unique_ptr<Slot[]> slots_;
  mutable std::size_t hot_page_ = SIZE_MAX;
  mutable double* hot_values_ = nullptr;
  mutable bool hot_dirty_ = false;
  mutable Slot* hot_slot_ = nullptr;
  mutable std::uint64_t clock_ = 0;
  mutable std::size_t file_pages_ = 0;  // pages [0, file_pages_) may be in the file
  mutable int fd_ = -1;
};

}  // namespace cal
