#pragma once
// A small checked layer over HDF5's C API, private to the library: every call's result is checked
// and a failure throws ResultsError with what was being done and HDF5's own reason; handles close
// themselves (never throwing). HDF5's automatic error printing is switched off only inside a
// Quiet scope and restored after, so a caller's settings (h5py's, in the same Python process)
// stay as they were.
#include <hdf5.h>

#include <string>
#include <utility>
#include <vector>

#include "errors.hpp"

namespace rfem::h5 {

/// Suppresses HDF5's error printing in its scope (and clears the error stack on entry).
class Quiet {
 public:
  Quiet();
  ~Quiet();
  Quiet(const Quiet&) = delete;
  Quiet& operator=(const Quiet&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

/// The innermost message on HDF5's error stack ("" if empty); clears the stack.
std::string reason();
/// Throws ResultsError("WHAT: reason") if `id` < 0; returns it otherwise.
hid_t check(hid_t id, const std::string& what);
/// Throws ResultsError("WHAT: reason") if `status` < 0.
void check(herr_t status, const std::string& what);

/// An HDF5 identifier closed by the matching H5*close when the handle dies (move-only).
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer close) : id_(id), close_(close) {}
  Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, -1)), close_(o.close_) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, -1);
      close_ = o.close_;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }
  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }
  bool valid() const { return id_ >= 0; }
  /// Closes now; returns false if HDF5 reported a failure (never throws).
  bool reset();
  /// Closes now and throws ResultsError("WHAT: reason") if that fails (a close flushes).
  void close(const std::string& what);

 private:
  hid_t id_ = -1;
  Closer close_ = nullptr;
};

Handle file(hid_t id, const std::string& what);
Handle group(hid_t id, const std::string& what);
Handle dataset(hid_t id, const std::string& what);
Handle space(hid_t id, const std::string& what);
Handle type(hid_t id, const std::string& what);
Handle plist(hid_t id, const std::string& what);
Handle attribute(hid_t id, const std::string& what);
Handle object(hid_t id, const std::string& what);

/// A dataset-creation list for a fixed-size table of `dims`: chunked (the whole table one chunk, at
/// most 64k values a chunk) with HDF5's Fletcher-32 checksum, so damaged values fail on read. An
/// empty table (nothing to check, and HDF5 chunks no zero extent) gets the default list.
Handle checked_layout(int rank, const hsize_t* dims, const std::string& what);
/// Adds the Fletcher-32 checksum filter to a dataset-creation list (chunked: every filter needs chunks).
void checksummed(hid_t dcpl, const std::string& what);

/// Variable-length UTF-8 strings: h5py reads them as str.
Handle string_type();
/// Attributes (replacing one of the same name), strings as variable-length UTF-8.
void write_attribute(hid_t obj, const std::string& key, const std::string& value);
void write_attribute(hid_t obj, const std::string& key, const std::vector<std::string>& values);
void write_attribute(hid_t obj, const std::string& key, double value);
void write_attribute(hid_t obj, const std::string& key, long value);
/// A string attribute (variable- or fixed-length); false if there is none.
bool read_string_attribute(hid_t obj, const std::string& key, std::string& value);

}  // namespace rfem::h5
