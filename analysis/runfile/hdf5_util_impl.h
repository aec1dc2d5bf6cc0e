// Private to analysis/runfile: thin RAII and helpers over the HDF5 C API.
// The only header of the module that includes hdf5.h.
#ifndef ADSE_ANALYSIS_RUNFILE_HDF5_UTIL_IMPL_H_
#define ADSE_ANALYSIS_RUNFILE_HDF5_UTIL_IMPL_H_

#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "stack/base/env.h"
#include "stack/base/status.h"

namespace adse::runfile::internal {

// Held for the duration of every public call: serializes HDF5 use (the
// library may be built without thread safety) and turns off HDF5's own
// error printing, restoring the caller's setting afterwards.
class Hdf5Session {
 public:
  Hdf5Session();
  ~Hdf5Session();
  Hdf5Session(const Hdf5Session&) = delete;
  Hdf5Session& operator=(const Hdf5Session&) = delete;

 private:
  std::unique_lock<std::mutex> lock_;
  H5E_auto2_t saved_func_ = nullptr;
  void* saved_data_ = nullptr;
  bool restore_ = false;
};

// Owns one HDF5 id of any kind and closes it on destruction.
class Handle {
 public:
  Handle() = default;
  explicit Handle(hid_t id) : id_(id) {}
  ~Handle() { Reset(); }
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, -1)) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      Reset();
      id_ = std::exchange(other.id_, -1);
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Closes now; false if HDF5 reported an error (e.g. a failed flush).
  bool Close();
  void Reset() { (void)Close(); }

 private:
  hid_t id_ = -1;
};

// The innermost description on HDF5's error stack of this thread (the most
// specific one, e.g. "truncated file: eof = ..."), then clears the stack.
std::string TakeHdf5Error();

// ---------------------------------------------------------------------------
// Whole files (used by run files and the campaign index alike).

// Writes a new HDF5 file at `path` atomically: creates the parent folders,
// creates `<path>.tmp.<host>.<pid>` (MakeFileAccessProps), calls
// `write_contents` on it inside an Hdf5Session, closes it and commits it
// through `env` (adse::CommitTemporary: fsync, rename over `path`, fsync of
// the folder). So readers see the old file or
// the whole new one. Errors of `write_contents` get the temporary's name as
// context; file system failures are IoError. No temporary is left behind on
// failure.
Status WriteFileAtomically(
    const std::string& path,
    const std::function<Status(hid_t file)>& write_contents, Env* env);

// Opens the HDF5 file `path` read-only and calls `read_contents` inside an
// Hdf5Session. NotFound if `path` does not exist; InvalidArgument if it is a
// folder (`expected` names what should be there, e.g. "a run file"); IoError
// if it cannot be read at all; Corruption "<path>: ..." if it is not HDF5,
// cannot be opened (truncated, damaged) or `read_contents` fails (whose
// message, naming the HDF5 object, then follows the path).
Status ReadFileContents(const std::string& path, const std::string& expected,
                        const std::function<Status(hid_t file)>& read_contents);

// Corruption when `path` holds a global heap collection (where variable-
// length strings live) that libhdf5 1.10 would loop forever on: one whose
// free-space object has size 0, so each step of HDF5's parse advances by
// nothing, or one whose object claims more bytes than the collection holds
// (HDF5 then copies overlapping memory). Found by fuzz_run_file
// (tests/fuzz/regressions/README.md); every reader calls it before H5Fopen.
Status CheckGlobalHeaps(const std::string& path);

// File access properties: the HDF5 1.10 file format (checksummed metadata)
// and no file locking (useless for write-once files and unsupported on some
// NFS/Lustre mounts, where it makes opens fail).
Handle MakeFileAccessProps();
// H5Fis_hdf5 / H5Fis_accessible: >0 HDF5, 0 not HDF5, <0 unreadable.
htri_t IsHdf5File(const std::string& path);
// Creation properties that leave out object timestamps, so the same run
// gives the same bytes.
Handle MakeGroupCreateProps();

// Creates group `name` below `parent` (no timestamps); IoError naming it.
Result<Handle> CreateGroup(hid_t parent, const std::string& name);
// Opens the group at absolute `path`; Corruption "<path>: missing group" if
// there is none.
Result<Handle> OpenGroup(hid_t file, const std::string& path);

// Moves a result's value into `*out`, or returns its error.
template <typename T>
Status Assign(Result<T> result, T* out) {
  if (!result.ok()) return result.status();
  *out = std::move(result).value();
  return Status::Ok();
}

enum class ObjectKind { kMissing, kGroup, kDataset, kOther };
// What `path` (absolute, '/'-separated) names below `file`; checks each
// component so that a missing parent is not an error.
ObjectKind GetObjectKind(hid_t file, const std::string& path);

// "float", "int", "string", "enum", "compound", ... for an HDF5 type class.
const char* TypeClassName(H5T_class_t type_class);

// Scalar attributes. Strings are written as fixed-length UTF-8 of their
// own size (see MakeFixedStringType); reads also accept variable-length.
// Numeric reads convert from any int/float.
Status WriteStringAttr(hid_t loc, const std::string& name,
                       const std::string& value);
Status WriteF64Attr(hid_t loc, const std::string& name, double value);
Status WriteI32Attr(hid_t loc, const std::string& name, int32_t value);
Status WriteI64Attr(hid_t loc, const std::string& name, int64_t value);
Status WriteU64Attr(hid_t loc, const std::string& name, uint64_t value);
// Whether `loc` has the attribute `name` (for attributes added later).
Result<bool> HasAttr(hid_t loc, const std::string& name);
Result<std::string> ReadStringAttr(hid_t loc, const std::string& name);
Result<double> ReadF64Attr(hid_t loc, const std::string& name);
Result<int64_t> ReadI64Attr(hid_t loc, const std::string& name);
Result<uint64_t> ReadU64Attr(hid_t loc, const std::string& name);
// 1-D string array attribute, fixed-length UTF-8 as wide as the longest
// value (at least 1 byte); may have no elements. InvalidArgument if a value
// holds a NUL byte. Reads also accept variable-length strings.
Status WriteStringListAttr(hid_t loc, const std::string& name,
                           const std::vector<std::string>& values);
Result<std::vector<std::string>> ReadStringListAttr(hid_t loc,
                                                    const std::string& name);
// Names of all attributes of `loc`, in name order.
Result<std::vector<std::string>> ListAttributes(hid_t loc);

// Scalar string dataset, written like string attributes.
Status WriteStringDataset(hid_t parent, const std::string& name,
                          const std::string& value);
Result<std::string> ReadStringDataset(hid_t parent, const std::string& name);

// Columns: 1-D datasets of one plain type, one element per row, stored like
// row datasets (chunked, shuffled, deflated, Fletcher-32 checksummed; 0 rows
// allowed), so h5py gives each as a numpy array and pandas as a Series.
// Numbers are little-endian float64/int64/uint64/uint8. Strings are
// fixed-length, NUL-padded UTF-8 as wide as the longest value (at least 1
// byte); InvalidArgument if a value holds a NUL byte.
Status WriteColumn(hid_t parent, const std::string& name,
                   const std::vector<double>& values);
Status WriteColumn(hid_t parent, const std::string& name,
                   const std::vector<int64_t>& values);
Status WriteColumn(hid_t parent, const std::string& name,
                   const std::vector<uint64_t>& values);
Status WriteColumn(hid_t parent, const std::string& name,
                   const std::vector<uint8_t>& values);
Status WriteColumn(hid_t parent, const std::string& name,
                   const std::vector<std::string>& values);
// Reads a column, converting to the C++ type. The file's type class must be
// float (double) or int (integer types); strings may be fixed or variable
// length. Corruption naming the dataset if it is missing, not 1-D, of
// another class or unreadable.
Status ReadColumn(hid_t parent, const std::string& name,
                  std::vector<double>* out);
Status ReadColumn(hid_t parent, const std::string& name,
                  std::vector<int64_t>* out);
Status ReadColumn(hid_t parent, const std::string& name,
                  std::vector<uint64_t>* out);
Status ReadColumn(hid_t parent, const std::string& name,
                  std::vector<uint8_t>* out);
Status ReadColumn(hid_t parent, const std::string& name,
                  std::vector<std::string>* out);

// ---------------------------------------------------------------------------
// Shared by the module's HDF5 files (hdf5_util.cc: errors; hdf5_strings.cc:
// string types and values), not meant for its readers and writers.

// Absolute HDF5 path of `name` below `loc`, for messages.
std::string PathOf(hid_t loc, const std::string& name);
// A read failure: Corruption; with the HDF5 error stack's innermost text.
Status ReadError(const std::string& what);
Status ReadHdf5Error(const std::string& object, const std::string& action);
// A write failure with the HDF5 error stack's text: IoError.
Status WriteHdf5Error(const std::string& object, const std::string& action);

// A fixed-length, NUL-padded UTF-8 string type of `bytes` (at least one
// byte), and one just long enough for `value`. Fixed rather than variable
// length: variable-length strings live in HDF5's global heap, which has no
// checksums, and a damaged heap crashes libhdf5 on read.
Handle MakeFixedStringTypeOfSize(size_t bytes);
Handle MakeFixedStringType(const std::string& value);
// `value` padded to its type's size (the empty string becomes one NUL).
std::vector<char> PaddedString(const std::string& value);
// Strings packed into one buffer of fixed-width, NUL-padded cells as wide
// as the longest value (at least 1 byte); a value holding a NUL is refused
// (InvalidArgument naming `what`), since it would end early on reading.
struct PackedStrings {
  size_t width = 1;
  std::vector<char> bytes;  // values.size() * width
};
Result<PackedStrings> PackStrings(const std::vector<std::string>& values,
                                  const std::string& what);
// The strings (variable or fixed length) of an attribute or dataset:
// `is_attr` picks H5Aread/H5Dread; `array` wants a 1-D array, otherwise
// exactly one string.
Result<std::vector<std::string>> ReadStrings(hid_t obj, bool is_attr,
                                             const std::string& what,
                                             bool array);
// The one string of an attribute or dataset.
Result<std::string> ReadScalarString(hid_t obj, bool is_attr,
                                     const std::string& what);

// One field of a compound row dataset. Rows are packed (no padding) in the
// order of the fields, in the file and in memory alike.
enum class FieldType { kFloat64, kInt32, kInt64, kUInt64, kEnum8, kString };
struct FieldDesc {
  std::string name;
  FieldType type = FieldType::kFloat64;
  size_t string_bytes = 0;                                  // kString only
  std::vector<std::pair<std::string, int8_t>> enum_values;  // kEnum8 only
  // Added after files of the same schema version were written: a file may
  // lack it, and readers then keep the row's default.
  bool optional = false;
};
size_t FieldSize(const FieldDesc& field);
size_t RowSize(const std::vector<FieldDesc>& fields);
// The HDF5 type class a field must have in a file.
H5T_class_t FieldClass(FieldType type);

// Writes `rows` packed rows as a 1-D chunked, compressed compound dataset
// in one H5Dwrite. `data` may be null when rows == 0.
Status WriteRows(hid_t parent, const std::string& name,
                 const std::vector<FieldDesc>& fields, size_t rows,
                 const char* data);

struct PackedRows {
  size_t rows = 0;
  // The fields read, in order: all but the optional ones the file lacks.
  std::vector<FieldDesc> fields;
  std::vector<char> bytes;  // rows * RowSize(fields)
};
// Reads a compound row dataset into packed rows, converting by field name
// (field order and extra fields in the file do not matter). Fails naming
// the dataset if it is missing, not 1-D compound, or lacks a field that is
// not optional.
Result<PackedRows> ReadRows(hid_t parent, const std::string& name,
                            const std::vector<FieldDesc>& fields);

}  // namespace adse::runfile::internal

#endif  // ADSE_ANALYSIS_RUNFILE_HDF5_UTIL_IMPL_H_
