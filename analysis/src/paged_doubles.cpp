// Doubles in bounded memory, paged to an unlinked temporary file (see paged_doubles.hpp).
#include "cal/analysis/paged_doubles.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

namespace cal {
namespace {

std::atomic<std::uint64_t> spilled{0};

std::string temp_dir() {
  const char* d = std::getenv("TMPDIR");
  return d && *d ? std::string(d) : std::string("/tmp");
}

}  // namespace

PagedDoubles::PagedDoubles(std::size_t size, PageOptions options) : options_(options) {
  if (options_.page_values < 2 || (options_.page_values & (options_.page_values - 1)) != 0 ||
      options_.pages_held < 1)
    throw std::invalid_argument(
        fmt::format("PagedDoubles: page of {} values (a power of two >= 2 needed), {} held",
                    options_.page_values, options_.pages_held));
  shift_ = 0;
  while ((std::size_t{1} << shift_) < options_.page_values) ++shift_;
  mask_ = options_.page_values - 1;
  size_ = size;  // zeros: pages never written read as zeros
}

PagedDoubles::PagedDoubles(PagedDoubles&& o) noexcept
    : options_(o.options_),
      shift_(o.shift_),
      mask_(o.mask_),
      size_(std::exchange(o.size_, 0)),
      slots_(std::move(o.slots_)),
      hot_page_(std::exchange(o.hot_page_, SIZE_MAX)),
      hot_values_(std::exchange(o.hot_values_, nullptr)),
      hot_dirty_(std::exchange(o.hot_dirty_, false)),
      hot_slot_(std::exchange(o.hot_slot_, nullptr)),
      clock_(o.clock_),
      file_pages_(std::exchange(o.file_pages_, 0)),
      fd_(std::exchange(o.fd_, -1)) {}

PagedDoubles& PagedDoubles::operator=(PagedDoubles&& o) noexcept {
  if (this == &o) return *this;
  if (fd_ >= 0) ::close(fd_);
  options_ = o.options_;
  shift_ = o.shift_;
  mask_ = o.mask_;
  size_ = std::exchange(o.size_, 0);
  slots_ = std::move(o.slots_);
  hot_page_ = std::exchange(o.hot_page_, SIZE_MAX);
  hot_values_ = std::exchange(o.hot_values_, nullptr);
  hot_dirty_ = std::exchange(o.hot_dirty_, false);
  hot_slot_ = std::exchange(o.hot_slot_, nullptr);
  clock_ = o.clock_;
  file_pages_ = std::exchange(o.file_pages_, 0);
  fd_ = std::exchange(o.fd_, -1);
  return *this;
}

PagedDoubles::~PagedDoubles() {
  if (fd_ >= 0) ::close(fd_);
}

PagedDoubles PagedDoubles::copy() const {
  PagedDoubles out(size_, options_);
  for (std::size_t i = 0; i < size_; ++i) out.set(i, (*this)[i]);
  return out;
}

std::uint64_t PagedDoubles::pages_spilled() { return spilled.load(); }

void PagedDoubles::open_file() const {
  const std::string dir = temp_dir();
#ifdef O_TMPFILE
  fd_ = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
#endif
  if (fd_ < 0) {  // no O_TMPFILE here: a named file, unlinked at once
    std::string name = dir + "/caldaq-pages-XXXXXX";
    fd_ = ::mkstemp(name.data());
    if (fd_ >= 0) ::unlink(name.c_str());
  }
  if (fd_ < 0)
    throw std::runtime_error(fmt::format(
        "cannot make a temporary file in {} for the values that do not fit in memory: {}", dir,
        std::strerror(errno)));
}

void PagedDoubles::write_back(Slot& s) const {
  if (!s.dirty) return;
  if (fd_ < 0) open_file();
  const std::size_t bytes = options_.page_values * sizeof(double);
  const auto at = static_cast<off_t>(s.page * bytes);
  const auto* p = reinterpret_cast<const char*>(s.values.get());
  for (std::size_t done = 0; done < bytes;) {
    const ssize_t w = ::pwrite(fd_, p + done, bytes - done, at + static_cast<off_t>(done));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0)
      throw std::runtime_error(
          fmt::format("cannot write the temporary file of values that do not fit in memory ({} "
                      "in {}): {}",
                      bytes, temp_dir(), w < 0 ? std::strerror(errno) : "no space"));
    done += static_cast<std::size_t>(w);
  }
  s.dirty = false;
  file_pages_ = std::max(file_pages_, s.page + 1);
  spilled.fetch_add(1);
}

void PagedDoubles::hot(std::size_t page, bool for_write) const {
  const std::size_t held = options_.pages_held;
  if (!slots_) slots_ = std::make_unique<Slot[]>(held);  // made on first use
  Slot* slot = nullptr;
  for (std::size_t k = 0; k < held && !slot; ++k)
    if (slots_[k].page == page) slot = &slots_[k];
  if (!slot) {  // the least recently used (an empty one first) is written back and reused
    slot = &slots_[0];
    for (std::size_t k = 1; k < held; ++k)
      if (slots_[k].used < slot->used) slot = &slots_[k];
    write_back(*slot);
    if (!slot->values) slot->values = std::make_unique<double[]>(options_.page_values);
    slot->page = page;
    double* v = slot->values.get();
    const std::size_t bytes = options_.page_values * sizeof(double);
    if (page < file_pages_) {
      auto* p = reinterpret_cast<char*>(v);
      const auto at = static_cast<off_t>(page * bytes);
      std::size_t done = 0;
      while (done < bytes) {
        const ssize_t r = ::pread(fd_, p + done, bytes - done, at + static_cast<off_t>(done));
        if (r < 0 && errno == EINTR) continue;
        if (r < 0)
          throw std::runtime_error(
              fmt::format("cannot read the temporary file of values that do not fit in memory: {}",
                          std::strerror(errno)));
        if (r == 0) break;  // past the end: never written, zeros
        done += static_cast<std::size_t>(r);
      }
      std::memset(p + done, 0, bytes - done);
    } else {
      std::fill(v, v + options_.page_values, 0.0);
    }
  }
  slot->used = ++clock_;
  if (for_write) slot->dirty = true;
  hot_slot_ = slot;
  hot_page_ = page;
  hot_values_ = slot->values.get();
  hot_dirty_ = slot->dirty;
}

}  // namespace cal
