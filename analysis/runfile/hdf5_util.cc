#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <limits>

#include "analysis/runfile/hdf5_util_impl.h"
#include "stack/base/files.h"

namespace adse::runfile::internal {
namespace {

std::mutex& Hdf5Mutex() {
  static std::mutex mutex;
  return mutex;
}

// Chunks of at most this many rows (and bytes): small enough for HDF5's
// default 1 MiB chunk cache, big enough that per-chunk overhead vanishes.
constexpr size_t kMaxChunkRows = 4096;
constexpr size_t kMaxChunkBytes = 512 * 1024;
constexpr unsigned kDeflateLevel = 4;

herr_t CollectErrors(unsigned /*n*/, const H5E_error2_t* err, void* data) {
  auto* out = static_cast<std::vector<std::string>*>(data);
  if (err != nullptr && err->desc != nullptr && err->desc[0] != '\0') {
    out->push_back(err->desc);
  }
  return 0;
}

// Absolute HDF5 path of `name` below `loc`, for messages.
std::string PathOf(hid_t loc, const std::string& name) {
  char buffer[512];
  const ssize_t n = H5Iget_name(loc, buffer, sizeof(buffer));
  std::string parent = n > 0 ? std::string(buffer) : std::string("?");
  if (name.empty() || name == ".") return parent;
  if (parent.empty() || parent.back() != '/') parent += '/';
  return parent + name;
}

Status ReadError(const std::string& what) { return Status::Corruption(what); }
Status ReadHdf5Error(const std::string& object, const std::string& action) {
  return Status::Corruption(object + ": " + action + ": " + TakeHdf5Error());
}
Status WriteHdf5Error(const std::string& object, const std::string& action) {
  return Status::IoError(object + ": " + action + ": " + TakeHdf5Error());
}

// A fixed-length, NUL-padded UTF-8 string type of `bytes` (at least one
// byte: HDF5 has no empty strings). Fixed rather than variable length:
// variable-length strings live in HDF5's global heap, which has no
// checksums, and a damaged heap crashes libhdf5 on read.
Handle MakeFixedStringTypeOfSize(size_t bytes) {
  Handle type(H5Tcopy(H5T_C_S1));
  if (!type.valid() ||
      H5Tset_size(type.get(), std::max<size_t>(1, bytes)) < 0 ||
      H5Tset_strpad(type.get(), H5T_STR_NULLPAD) < 0 ||
      H5Tset_cset(type.get(), H5T_CSET_UTF8) < 0) {
    return Handle();
  }
  return type;
}

// A fixed-length string type just long enough for `value`.
Handle MakeFixedStringType(const std::string& value) {
  return MakeFixedStringTypeOfSize(value.size());
}

// Strings packed into one buffer of fixed-width, NUL-padded cells as wide as
// the longest value (at least 1 byte). A NUL inside a value would end it
// early on reading, so it is refused.
struct PackedStrings {
  size_t width = 1;
  std::vector<char> bytes;  // values.size() * width
};
Result<PackedStrings> PackStrings(const std::vector<std::string>& values,
                                  const std::string& what) {
  PackedStrings packed;
  for (size_t i = 0; i < values.size(); ++i) {
    if (values[i].find('\0') != std::string::npos) {
      return Status::InvalidArgument(what + ": value " + std::to_string(i) +
                                     " contains a NUL byte");
    }
    packed.width = std::max(packed.width, values[i].size());
  }
  packed.bytes.assign(values.size() * packed.width, '\0');
  for (size_t i = 0; i < values.size(); ++i) {
    std::copy(
        values[i].begin(), values[i].end(),
        packed.bytes.begin() + static_cast<std::ptrdiff_t>(i * packed.width));
  }
  return packed;
}

// Creation properties of a 1-D row or column dataset of `rows` elements of
// `row_size` bytes: chunked, shuffled, deflated, Fletcher-32, no timestamps.
Handle MakeRowsCreateProps(size_t rows, size_t row_size) {
  row_size = std::max<size_t>(1, row_size);
  size_t chunk_rows =
      std::clamp<size_t>(kMaxChunkBytes / row_size, 1, kMaxChunkRows);
  if (rows > 0) chunk_rows = std::min(chunk_rows, rows);
  const hsize_t chunk[1] = {static_cast<hsize_t>(chunk_rows)};
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE));
  if (!dcpl.valid() || H5Pset_chunk(dcpl.get(), 1, chunk) < 0 ||
      H5Pset_shuffle(dcpl.get()) < 0 ||
      H5Pset_deflate(dcpl.get(), kDeflateLevel) < 0 ||
      H5Pset_fletcher32(dcpl.get()) < 0 ||
      H5Pset_obj_track_times(dcpl.get(), false) < 0) {
    return Handle();
  }
  return dcpl;
}

// Creates the 1-D dataset `name` of `rows` elements (unlimited maximum) and
// writes `data` (which may be null when rows == 0) in one H5Dwrite.
Status WriteOneDimensional(hid_t parent, const std::string& name,
                           hid_t file_type, hid_t mem_type, size_t rows,
                           const void* data) {
  const std::string what = PathOf(parent, name);
  const hsize_t dims[1] = {static_cast<hsize_t>(rows)};
  const hsize_t max_dims[1] = {H5S_UNLIMITED};
  Handle space(H5Screate_simple(1, dims, max_dims));
  Handle dcpl = MakeRowsCreateProps(rows, H5Tget_size(file_type));
  if (!space.valid() || !dcpl.valid()) {
    return WriteHdf5Error(what, "preparing");
  }
  Handle dataset(H5Dcreate2(parent, name.c_str(), file_type, space.get(),
                            H5P_DEFAULT, dcpl.get(), H5P_DEFAULT));
  if (!dataset.valid()) return WriteHdf5Error(what, "creating");
  if (rows > 0 && H5Dwrite(dataset.get(), mem_type, H5S_ALL, H5S_ALL,
                           H5P_DEFAULT, data) < 0) {
    return WriteHdf5Error(what, "writing " + std::to_string(rows) + " rows");
  }
  if (!dataset.Close()) return WriteHdf5Error(what, "closing");
  return Status::Ok();
}

// A 1-D dataset opened for reading, its class checked.
struct OpenColumn {
  std::string what;
  Handle dataset;
  Handle type;
  Handle space;
  size_t rows = 0;
};
Result<OpenColumn> OpenColumnDataset(hid_t parent, const std::string& name,
                                     H5T_class_t wanted) {
  OpenColumn column;
  column.what = PathOf(parent, name);
  const std::string& what = column.what;
  if (GetObjectKind(parent, what) != ObjectKind::kDataset) {
    return ReadError(what + ": missing dataset");
  }
  column.dataset = Handle(H5Dopen2(parent, name.c_str(), H5P_DEFAULT));
  if (!column.dataset.valid()) return ReadHdf5Error(what, "opening");
  column.type = Handle(H5Dget_type(column.dataset.get()));
  column.space = Handle(H5Dget_space(column.dataset.get()));
  if (!column.type.valid() || !column.space.valid()) {
    return ReadHdf5Error(what, "type");
  }
  const H5T_class_t type_class = H5Tget_class(column.type.get());
  if (type_class != wanted) {
    return ReadError(what + ": is " + TypeClassName(type_class) +
                     ", expected " + TypeClassName(wanted));
  }
  if (H5Sget_simple_extent_ndims(column.space.get()) != 1) {
    return ReadError(what + ": expected a 1-D dataset (one value per row)");
  }
  hsize_t dims[1] = {0};
  if (H5Sget_simple_extent_dims(column.space.get(), dims, nullptr) < 0) {
    return ReadHdf5Error(what, "shape");
  }
  column.rows = static_cast<size_t>(dims[0]);
  return column;
}

template <typename T>
Status ReadNumericColumn(hid_t parent, const std::string& name,
                         H5T_class_t wanted, hid_t mem_type,
                         std::vector<T>* out) {
  Result<OpenColumn> column = OpenColumnDataset(parent, name, wanted);
  if (!column.ok()) return column.status();
  out->assign(column->rows, T{});
  if (column->rows > 0 && H5Dread(column->dataset.get(), mem_type, H5S_ALL,
                                  H5S_ALL, H5P_DEFAULT, out->data()) < 0) {
    return ReadHdf5Error(column->what,
                         "reading " + std::to_string(column->rows) + " rows");
  }
  return Status::Ok();
}

// Reads the strings (variable or fixed length) of an attribute or dataset:
// `is_attr` picks H5Aread/H5Dread; `array` wants a 1-D array, otherwise
// exactly one string.
Result<std::vector<std::string>> ReadStrings(hid_t obj, bool is_attr,
                                             const std::string& what,
                                             bool array) {
  Handle type(is_attr ? H5Aget_type(obj) : H5Dget_type(obj));
  Handle space(is_attr ? H5Aget_space(obj) : H5Dget_space(obj));
  if (!type.valid() || !space.valid()) return ReadHdf5Error(what, "type");
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class != H5T_STRING) {
    return ReadError(what + " is " + TypeClassName(type_class) +
                     (array ? ", expected strings" : ", expected a string"));
  }
  if (array && H5Sget_simple_extent_ndims(space.get()) != 1) {
    return ReadError(what + ": expected a 1-D array of strings");
  }
  if (!array && H5Sget_simple_extent_npoints(space.get()) != 1) {
    return ReadError(what + " is not a single string");
  }
  const hssize_t points = H5Sget_simple_extent_npoints(space.get());
  if (points < 0) return ReadHdf5Error(what, "shape");
  const size_t n = static_cast<size_t>(points);
  std::vector<std::string> values(n);
  if (n == 0) return values;
  const htri_t variable = H5Tis_variable_str(type.get());
  if (variable < 0) return ReadHdf5Error(what, "type");
  if (variable > 0) {
    Handle mem_type(H5Tcopy(type.get()));  // keeps the file's charset
    std::vector<char*> texts(n, nullptr);
    const herr_t rc = is_attr ? H5Aread(obj, mem_type.get(), texts.data())
                              : H5Dread(obj, mem_type.get(), H5S_ALL, H5S_ALL,
                                        H5P_DEFAULT, texts.data());
    // Taken before the reclaim, whose call clears HDF5's error stack.
    const Status status =
        rc < 0 ? ReadHdf5Error(what, "reading") : Status::Ok();
    if (status.ok()) {
      for (size_t i = 0; i < n; ++i) {
        if (texts[i] != nullptr) values[i] = texts[i];
      }
    }
    // Also after a failed read: HDF5 may have filled some strings before
    // failing on a damaged one, and they are ours to free.
#if H5_VERSION_GE(1, 12, 0)
    H5Treclaim(mem_type.get(), space.get(), H5P_DEFAULT, texts.data());
#else
    H5Dvlen_reclaim(mem_type.get(), space.get(), H5P_DEFAULT, texts.data());
#endif
    if (!status.ok()) return status;
    return values;
  }
  const size_t width = H5Tget_size(type.get());
  if (width == 0) return ReadHdf5Error(what, "type size");
  if (n > std::numeric_limits<size_t>::max() / width) {
    return ReadError(what + ": implausible size");
  }
  std::vector<char> buffer(n * width, '\0');
  const herr_t rc = is_attr ? H5Aread(obj, type.get(), buffer.data())
                            : H5Dread(obj, type.get(), H5S_ALL, H5S_ALL,
                                      H5P_DEFAULT, buffer.data());
  if (rc < 0) return ReadHdf5Error(what, "reading");
  for (size_t i = 0; i < n; ++i) {
    const char* cell = buffer.data() + i * width;
    values[i].assign(cell, ::strnlen(cell, width));
  }
  return values;
}

// `value` padded to the type's size (the empty string becomes one NUL).
std::vector<char> PaddedString(const std::string& value) {
  std::vector<char> bytes(std::max<size_t>(1, value.size()), '\0');
  std::copy(value.begin(), value.end(), bytes.begin());
  return bytes;
}

// Builds the packed compound for `fields`; `file` picks little-endian
// standard types (what goes to disk) over native ones (memory). On x86 the
// two are equal, so writes and reads need no conversion.
Handle MakeCompoundType(const std::vector<FieldDesc>& fields, bool file) {
  Handle compound(H5Tcreate(H5T_COMPOUND, RowSize(fields)));
  if (!compound.valid()) return Handle();
  size_t offset = 0;
  for (const FieldDesc& field : fields) {
    Handle member;
    switch (field.type) {
      case FieldType::kFloat64:
        member = Handle(H5Tcopy(file ? H5T_IEEE_F64LE : H5T_NATIVE_DOUBLE));
        break;
      case FieldType::kInt32:
        member = Handle(H5Tcopy(file ? H5T_STD_I32LE : H5T_NATIVE_INT32));
        break;
      case FieldType::kInt64:
        member = Handle(H5Tcopy(file ? H5T_STD_I64LE : H5T_NATIVE_INT64));
        break;
      case FieldType::kUInt64:
        member = Handle(H5Tcopy(file ? H5T_STD_U64LE : H5T_NATIVE_UINT64));
        break;
      case FieldType::kEnum8: {
        member = Handle(H5Tenum_create(file ? H5T_STD_I8LE : H5T_NATIVE_INT8));
        if (!member.valid()) return Handle();
        for (const auto& [value_name, value] : field.enum_values) {
          int8_t v = value;
          if (H5Tenum_insert(member.get(), value_name.c_str(), &v) < 0) {
            return Handle();
          }
        }
        break;
      }
      case FieldType::kString:
        member = Handle(H5Tcopy(H5T_C_S1));
        if (!member.valid() ||
            H5Tset_size(member.get(), field.string_bytes) < 0 ||
            H5Tset_strpad(member.get(), H5T_STR_NULLPAD) < 0 ||
            H5Tset_cset(member.get(), H5T_CSET_UTF8) < 0) {
          return Handle();
        }
        break;
    }
    if (!member.valid() || H5Tinsert(compound.get(), field.name.c_str(), offset,
                                     member.get()) < 0) {
      return Handle();
    }
    offset += FieldSize(field);
  }
  return compound;
}

// The attribute `name` of `loc`, or a Corruption naming it.
Result<Handle> OpenAttr(hid_t loc, const std::string& name) {
  const htri_t exists = H5Aexists(loc, name.c_str());
  if (exists < 0) return ReadHdf5Error(PathOf(loc, ""), "attribute " + name);
  if (exists == 0) {
    return ReadError(PathOf(loc, "") + ": missing attribute '" + name + "'");
  }
  Handle attr(H5Aopen(loc, name.c_str(), H5P_DEFAULT));
  if (!attr.valid()) {
    return ReadHdf5Error(PathOf(loc, ""), "opening attribute '" + name + "'");
  }
  return attr;
}

// Reads a one-element numeric attribute converted to `mem_type`.
template <typename T>
Result<T> ReadNumericAttr(hid_t loc, const std::string& name, hid_t mem_type) {
  Result<Handle> attr = OpenAttr(loc, name);
  if (!attr.ok()) return attr.status();
  const std::string what = PathOf(loc, "") + ": attribute '" + name + "'";
  Handle type(H5Aget_type(attr->get()));
  Handle space(H5Aget_space(attr->get()));
  if (!type.valid() || !space.valid()) return ReadHdf5Error(what, "type");
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class != H5T_FLOAT && type_class != H5T_INTEGER) {
    return ReadError(what + " is " + TypeClassName(type_class) +
                     ", expected a number");
  }
  if (H5Sget_simple_extent_npoints(space.get()) != 1) {
    return ReadError(what + " is not a single value");
  }
  T value{};
  if (H5Aread(attr->get(), mem_type, &value) < 0) {
    return ReadHdf5Error(what, "reading");
  }
  return value;
}

// Reads a one-element string (variable or fixed length) from an attribute
// or dataset: `is_attr` picks H5Aread/H5Dread.
Result<std::string> ReadScalarString(hid_t obj, bool is_attr,
                                     const std::string& what) {
  Result<std::vector<std::string>> one =
      ReadStrings(obj, is_attr, what, /*array=*/false);
  if (!one.ok()) return one.status();
  return std::move(one->front());
}

// Creates (replacing) an attribute and writes its value(s): a scalar when
// `count` is null, else a 1-D array of *count elements.
Status WriteAttr(hid_t loc, const std::string& name, hid_t file_type,
                 hid_t mem_type, const void* value,
                 const size_t* count = nullptr) {
  const std::string what = PathOf(loc, "") + ": attribute '" + name + "'";
  const htri_t exists = H5Aexists(loc, name.c_str());
  if (exists < 0) return WriteHdf5Error(what, "checking");
  if (exists > 0 && H5Adelete(loc, name.c_str()) < 0) {
    return WriteHdf5Error(what, "replacing");
  }
  const hsize_t dims[1] = {count != nullptr ? static_cast<hsize_t>(*count) : 0};
  Handle space(count != nullptr ? H5Screate_simple(1, dims, nullptr)
                                : H5Screate(H5S_SCALAR));
  if (!space.valid()) return WriteHdf5Error(what, "dataspace");
  Handle attr(H5Acreate2(loc, name.c_str(), file_type, space.get(), H5P_DEFAULT,
                         H5P_DEFAULT));
  if (!attr.valid()) return WriteHdf5Error(what, "creating");
  if ((count == nullptr || *count > 0) &&
      H5Awrite(attr.get(), mem_type, value) < 0) {
    return WriteHdf5Error(what, "writing");
  }
  if (!attr.Close()) return WriteHdf5Error(what, "closing");
  return Status::Ok();
}

herr_t CollectAttrName(hid_t /*loc*/, const char* name,
                       const H5A_info_t* /*info*/, void* data) {
  static_cast<std::vector<std::string>*>(data)->push_back(name);
  return 0;
}

}  // namespace

Hdf5Session::Hdf5Session() : lock_(Hdf5Mutex()) {
  if (H5Eget_auto2(H5E_DEFAULT, &saved_func_, &saved_data_) >= 0) {
    restore_ = true;
  }
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

Hdf5Session::~Hdf5Session() {
  H5Eclear2(H5E_DEFAULT);
  if (restore_) H5Eset_auto2(H5E_DEFAULT, saved_func_, saved_data_);
}

bool Handle::Close() {
  if (id_ < 0) return true;
  const hid_t id = std::exchange(id_, -1);
  herr_t rc = -1;
  switch (H5Iget_type(id)) {
    case H5I_FILE:
      rc = H5Fclose(id);
      break;
    case H5I_GROUP:
      rc = H5Gclose(id);
      break;
    case H5I_DATASET:
      rc = H5Dclose(id);
      break;
    case H5I_DATASPACE:
      rc = H5Sclose(id);
      break;
    case H5I_DATATYPE:
      rc = H5Tclose(id);
      break;
    case H5I_ATTR:
      rc = H5Aclose(id);
      break;
    case H5I_GENPROP_LST:
      rc = H5Pclose(id);
      break;
    default:
      rc = H5Idec_ref(id) < 0 ? -1 : 0;
      break;
  }
  return rc >= 0;
}

std::string TakeHdf5Error() {
  std::vector<std::string> descriptions;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, CollectErrors, &descriptions);
  H5Eclear2(H5E_DEFAULT);
  if (descriptions.empty()) return "unknown HDF5 error";
  // Downward: from the API call to the deepest cause. Name both when they
  // differ, e.g. "unable to open file (truncated file: eof = ...)".
  if (descriptions.size() == 1) return descriptions.front();
  return descriptions.front() + " (" + descriptions.back() + ")";
}

Status WriteFileAtomically(
    const std::string& path,
    const std::function<Status(hid_t file)>& write_contents, Env* env) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  if (target.has_parent_path()) {
    ADSE_RETURN_IF_ERROR(MakeDirs(target.parent_path().string(), env));
  }
  const std::string tmp = TemporaryPathFor(path);
  Status status;
  {
    Hdf5Session session;
    Handle fapl = MakeFileAccessProps();
    // No modification time on the root group either, so the same contents
    // give the same bytes (datasets and groups already track none).
    Handle fcpl(H5Pcreate(H5P_FILE_CREATE));
    if (fcpl.valid()) H5Pset_obj_track_times(fcpl.get(), false);
    Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC,
                          fcpl.valid() ? fcpl.get() : H5P_DEFAULT, fapl.get()));
    if (!file.valid()) {
      status = Status::IoError(tmp +
                               ": cannot create HDF5 file: " + TakeHdf5Error());
    } else {
      status = write_contents(file.get()).WithContext(tmp);
      // Closing flushes metadata; a failure here means the file is bad.
      if (!file.Close() && status.ok()) {
        status = Status::IoError(tmp + ": closing: " + TakeHdf5Error());
      }
    }
  }
  if (!status.ok()) {
    (void)env->RemoveFile(tmp);
    return status;
  }
  return CommitTemporary(tmp, path, env);
}

// The walk mirrors the collection layout of the HDF5 file
// format (version 1, 8-byte lengths, what adse and h5py write): "GCOL",
// version, 3 reserved bytes, collection size, then objects of a 16-byte
// header (index, references, reserved, size) and 8-byte aligned data.
Status CheckGlobalHeaps(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    return Status::IoError(path + ": cannot read: " + std::strerror(errno));
  }
  struct stat info;
  void* map = MAP_FAILED;
  size_t n = 0;
  if (::fstat(fd, &info) == 0 && info.st_size > 0) {
    n = static_cast<size_t>(info.st_size);
    map = ::mmap(nullptr, n, PROT_READ, MAP_PRIVATE, fd, 0);
  }
  const int error = errno;
  ::close(fd);  // the mapping stays valid
  if (n == 0) return Status::Ok();
  if (map == MAP_FAILED) {
    return Status::IoError(path + ": cannot read: " + std::strerror(error));
  }
  const unsigned char* bytes = static_cast<const unsigned char*>(map);
  auto u64 = [&](size_t at) {
    uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = (v << 8) | bytes[at + i];
    return v;
  };
  constexpr size_t kHeader = 16, kMinCollection = 4096;
  Status status;
  for (size_t at = 0; status.ok() && at + kHeader <= n; ++at) {
    at = static_cast<size_t>(
        std::search(bytes + at, bytes + n, "GCOL", "GCOL" + 4) - bytes);
    if (at + kHeader > n) break;
    const uint64_t size = u64(at + 8);
    if (bytes[at + 4] != 1 || size < kMinCollection || size > n - at) {
      continue;  // not a collection header (e.g. the text "GCOL" in data)
    }
    const size_t end = at + static_cast<size_t>(size);
    for (size_t p = at + kHeader; p + kHeader <= end;) {
      const unsigned index = bytes[p] | (bytes[p + 1] << 8);
      const uint64_t object = u64(p + 8);
      const uint64_t room = end - p;  // bytes left in the collection
      if (index == 0) {               // free space; HDF5 parses on after it
        if (object == 0) {
          status = Status::Corruption(
              path + ": damaged HDF5 global heap at byte " +
              std::to_string(at) +
              " (an empty free-space object, which HDF5 cannot read past)");
          break;
        }
        if (object > room) break;  // trailing free space
        p += static_cast<size_t>(object);
        continue;
      }
      // Compared before any arithmetic: a size near 2^64 must not wrap.
      if (object > room - kHeader || kHeader + ((object + 7) / 8) * 8 > room) {
        status = Status::Corruption(
            path + ": damaged HDF5 global heap at byte " + std::to_string(at) +
            " (object " + std::to_string(index) + " claims " +
            std::to_string(object) + " bytes, more than its collection)");
        break;
      }
      p += static_cast<size_t>(kHeader + ((object + 7) / 8) * 8);
    }
  }
  ::munmap(map, n);
  return status;
}

Status ReadFileContents(
    const std::string& path, const std::string& expected,
    const std::function<Status(hid_t file)>& read_contents) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::NotFound(path + ": no such file");
  if (fs::is_directory(path, ec)) {
    return Status::InvalidArgument(path + ": is a directory, expected " +
                                   expected);
  }
  Hdf5Session session;
  const htri_t is_hdf5 = IsHdf5File(path);
  if (is_hdf5 < 0) {
    return Status::IoError(path + ": cannot read: " + TakeHdf5Error());
  }
  if (is_hdf5 == 0) {
    return Status::Corruption(path + ": not an HDF5 file (no HDF5 signature)");
  }
  ADSE_RETURN_IF_ERROR(CheckGlobalHeaps(path));
  Handle fapl = MakeFileAccessProps();
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()));
  if (!file.valid()) {
    return Status::Corruption(path +
                              ": cannot open as HDF5 (truncated or "
                              "damaged?): " +
                              TakeHdf5Error());
  }
  Status status = read_contents(file.get());
  if (!status.ok()) return Status::Corruption(path + ": " + status.message());
  return Status::Ok();
}

Handle MakeFileAccessProps() {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS));
  if (!fapl.valid()) return fapl;
#if H5_VERSION_GE(1, 10, 7)
  H5Pset_file_locking(fapl.get(), /*use_file_locking=*/false,
                      /*ignore_when_disabled=*/true);
#endif
  // Closing the file id really closes the file, whatever ids leak.
  H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG);
  // The 1.10 file format checksums all metadata, so damage is reported
  // instead of being read (or crashing libhdf5). Pinned, not "latest", so
  // files stay readable by HDF5 1.10+ whatever library adse is built with.
#if H5_VERSION_GE(1, 10, 2)
  H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V110, H5F_LIBVER_V110);
#endif
  return fapl;
}

htri_t IsHdf5File(const std::string& path) {
#if H5_VERSION_GE(1, 12, 0)
  Handle fapl = MakeFileAccessProps();
  return H5Fis_accessible(path.c_str(), fapl.get());
#else
  return H5Fis_hdf5(path.c_str());
#endif
}

Handle MakeGroupCreateProps() {
  Handle gcpl(H5Pcreate(H5P_GROUP_CREATE));
  if (gcpl.valid()) H5Pset_obj_track_times(gcpl.get(), false);
  return gcpl;
}

Result<Handle> CreateGroup(hid_t parent, const std::string& name) {
  Handle gcpl = MakeGroupCreateProps();
  Handle group(
      H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT));
  if (!group.valid()) {
    return Status::IoError("creating group " + PathOf(parent, name) + ": " +
                           TakeHdf5Error());
  }
  return group;
}

Result<Handle> OpenGroup(hid_t file, const std::string& path) {
  if (GetObjectKind(file, path) != ObjectKind::kGroup) {
    return Status::Corruption(path + ": missing group");
  }
  Handle group(H5Gopen2(file, path.c_str(), H5P_DEFAULT));
  if (!group.valid()) {
    return Status::Corruption(path + ": opening: " + TakeHdf5Error());
  }
  return group;
}

ObjectKind GetObjectKind(hid_t file, const std::string& path) {
  // H5Lexists fails (rather than returning 0) on a missing parent, so walk
  // the components.
  size_t pos = 0;
  while (pos != std::string::npos) {
    pos = path.find('/', pos + 1);
    const std::string prefix = path.substr(0, pos);
    if (prefix.empty() || prefix == "/") continue;
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return ObjectKind::kMissing;
    }
  }
  Handle object(H5Oopen(file, path.c_str(), H5P_DEFAULT));
  if (!object.valid()) {
    H5Eclear2(H5E_DEFAULT);
    return ObjectKind::kOther;  // e.g. a dangling soft link
  }
  switch (H5Iget_type(object.get())) {
    case H5I_GROUP:
      return ObjectKind::kGroup;
    case H5I_DATASET:
      return ObjectKind::kDataset;
    default:
      return ObjectKind::kOther;
  }
}

const char* TypeClassName(H5T_class_t type_class) {
  switch (type_class) {
    case H5T_INTEGER:
      return "int";
    case H5T_FLOAT:
      return "float";
    case H5T_STRING:
      return "string";
    case H5T_ENUM:
      return "enum";
    case H5T_COMPOUND:
      return "compound";
    case H5T_TIME:
      return "time";
    case H5T_BITFIELD:
      return "bitfield";
    case H5T_OPAQUE:
      return "opaque";
    case H5T_REFERENCE:
      return "reference";
    case H5T_VLEN:
      return "vlen";
    case H5T_ARRAY:
      return "array";
    default:
      return "unknown";
  }
}

Status WriteStringAttr(hid_t loc, const std::string& name,
                       const std::string& value) {
  Handle type = MakeFixedStringType(value);
  if (!type.valid()) return WriteHdf5Error(PathOf(loc, ""), "string type");
  const std::vector<char> bytes = PaddedString(value);
  return WriteAttr(loc, name, type.get(), type.get(), bytes.data());
}

Status WriteF64Attr(hid_t loc, const std::string& name, double value) {
  return WriteAttr(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

Status WriteI32Attr(hid_t loc, const std::string& name, int32_t value) {
  return WriteAttr(loc, name, H5T_STD_I32LE, H5T_NATIVE_INT32, &value);
}

Status WriteI64Attr(hid_t loc, const std::string& name, int64_t value) {
  return WriteAttr(loc, name, H5T_STD_I64LE, H5T_NATIVE_INT64, &value);
}

Status WriteU64Attr(hid_t loc, const std::string& name, uint64_t value) {
  return WriteAttr(loc, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, &value);
}

Status WriteStringListAttr(hid_t loc, const std::string& name,
                           const std::vector<std::string>& values) {
  const std::string what = PathOf(loc, "") + ": attribute '" + name + "'";
  Result<PackedStrings> packed = PackStrings(values, what);
  if (!packed.ok()) return packed.status();
  Handle type = MakeFixedStringTypeOfSize(packed->width);
  if (!type.valid()) return WriteHdf5Error(what, "string type");
  const size_t count = values.size();
  return WriteAttr(loc, name, type.get(), type.get(), packed->bytes.data(),
                   &count);
}

Result<std::vector<std::string>> ReadStringListAttr(hid_t loc,
                                                    const std::string& name) {
  Result<Handle> attr = OpenAttr(loc, name);
  if (!attr.ok()) return attr.status();
  return ReadStrings(attr->get(), /*is_attr=*/true,
                     PathOf(loc, "") + ": attribute '" + name + "'",
                     /*array=*/true);
}

Result<std::string> ReadStringAttr(hid_t loc, const std::string& name) {
  Result<Handle> attr = OpenAttr(loc, name);
  if (!attr.ok()) return attr.status();
  return ReadScalarString(attr->get(), /*is_attr=*/true,
                          PathOf(loc, "") + ": attribute '" + name + "'");
}

Result<double> ReadF64Attr(hid_t loc, const std::string& name) {
  return ReadNumericAttr<double>(loc, name, H5T_NATIVE_DOUBLE);
}

Result<int64_t> ReadI64Attr(hid_t loc, const std::string& name) {
  return ReadNumericAttr<int64_t>(loc, name, H5T_NATIVE_INT64);
}

Result<uint64_t> ReadU64Attr(hid_t loc, const std::string& name) {
  return ReadNumericAttr<uint64_t>(loc, name, H5T_NATIVE_UINT64);
}

Result<std::vector<std::string>> ListAttributes(hid_t loc) {
  std::vector<std::string> names;
  hsize_t index = 0;
  if (H5Aiterate2(loc, H5_INDEX_NAME, H5_ITER_INC, &index, CollectAttrName,
                  &names) < 0) {
    return ReadHdf5Error(PathOf(loc, ""), "listing attributes");
  }
  return names;
}

Status WriteStringDataset(hid_t parent, const std::string& name,
                          const std::string& value) {
  const std::string what = PathOf(parent, name);
  Handle type = MakeFixedStringType(value);
  Handle space(H5Screate(H5S_SCALAR));
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE));
  if (!type.valid() || !space.valid() || !dcpl.valid() ||
      H5Pset_obj_track_times(dcpl.get(), false) < 0) {
    return WriteHdf5Error(what, "preparing");
  }
  Handle dataset(H5Dcreate2(parent, name.c_str(), type.get(), space.get(),
                            H5P_DEFAULT, dcpl.get(), H5P_DEFAULT));
  if (!dataset.valid()) return WriteHdf5Error(what, "creating");
  const std::vector<char> bytes = PaddedString(value);
  if (H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT,
               bytes.data()) < 0) {
    return WriteHdf5Error(what, "writing");
  }
  if (!dataset.Close()) return WriteHdf5Error(what, "closing");
  return Status::Ok();
}

Result<std::string> ReadStringDataset(hid_t parent, const std::string& name) {
  const std::string what = PathOf(parent, name);
  const ObjectKind kind = GetObjectKind(parent, what);
  if (kind != ObjectKind::kDataset) {
    return ReadError(what + ": missing dataset");
  }
  Handle dataset(H5Dopen2(parent, name.c_str(), H5P_DEFAULT));
  if (!dataset.valid()) return ReadHdf5Error(what, "opening");
  return ReadScalarString(dataset.get(), /*is_attr=*/false, what);
}

Status WriteColumn(hid_t parent, const std::string& name,
                   const std::vector<double>& values) {
  return WriteOneDimensional(parent, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                             values.size(), values.data());
}

Status WriteColumn(hid_t parent, const std::string& name,
                   const std::vector<int64_t>& values) {
  return WriteOneDimensional(parent, name, H5T_STD_I64LE, H5T_NATIVE_INT64,
                             values.size(), values.data());
}

Status WriteColumn(hid_t parent, const std::string& name,
                   const std::vector<uint64_t>& values) {
  return WriteOneDimensional(parent, name, H5T_STD_U64LE, H5T_NATIVE_UINT64,
                             values.size(), values.data());
}

Status WriteColumn(hid_t parent, const std::string& name,
                   const std::vector<uint8_t>& values) {
  return WriteOneDimensional(parent, name, H5T_STD_U8LE, H5T_NATIVE_UINT8,
                             values.size(), values.data());
}

Status WriteColumn(hid_t parent, const std::string& name,
                   const std::vector<std::string>& values) {
  const std::string what = PathOf(parent, name);
  Result<PackedStrings> packed = PackStrings(values, what);
  if (!packed.ok()) return packed.status();
  Handle type = MakeFixedStringTypeOfSize(packed->width);
  if (!type.valid()) return WriteHdf5Error(what, "string type");
  return WriteOneDimensional(parent, name, type.get(), type.get(),
                             values.size(), packed->bytes.data());
}

Status ReadColumn(hid_t parent, const std::string& name,
                  std::vector<double>* out) {
  return ReadNumericColumn(parent, name, H5T_FLOAT, H5T_NATIVE_DOUBLE, out);
}

Status ReadColumn(hid_t parent, const std::string& name,
                  std::vector<int64_t>* out) {
  return ReadNumericColumn(parent, name, H5T_INTEGER, H5T_NATIVE_INT64, out);
}

Status ReadColumn(hid_t parent, const std::string& name,
                  std::vector<uint64_t>* out) {
  return ReadNumericColumn(parent, name, H5T_INTEGER, H5T_NATIVE_UINT64, out);
}

Status ReadColumn(hid_t parent, const std::string& name,
                  std::vector<uint8_t>* out) {
  return ReadNumericColumn(parent, name, H5T_INTEGER, H5T_NATIVE_UINT8, out);
}

Status ReadColumn(hid_t parent, const std::string& name,
                  std::vector<std::string>* out) {
  Result<OpenColumn> column = OpenColumnDataset(parent, name, H5T_STRING);
  if (!column.ok()) return column.status();
  return Assign(
      ReadStrings(column->dataset.get(), /*is_attr=*/false, column->what,
                  /*array=*/true),
      out);
}

size_t FieldSize(const FieldDesc& field) {
  switch (field.type) {
    case FieldType::kFloat64:
    case FieldType::kInt64:
    case FieldType::kUInt64:
      return 8;
    case FieldType::kInt32:
      return 4;
    case FieldType::kEnum8:
      return 1;
    case FieldType::kString:
      return field.string_bytes;
  }
  return 0;
}

size_t RowSize(const std::vector<FieldDesc>& fields) {
  size_t size = 0;
  for (const FieldDesc& field : fields) size += FieldSize(field);
  return size;
}

H5T_class_t FieldClass(FieldType type) {
  switch (type) {
    case FieldType::kFloat64:
      return H5T_FLOAT;
    case FieldType::kInt32:
    case FieldType::kInt64:
    case FieldType::kUInt64:
      return H5T_INTEGER;
    case FieldType::kEnum8:
      return H5T_ENUM;
    case FieldType::kString:
      return H5T_STRING;
  }
  return H5T_NO_CLASS;
}

Status WriteRows(hid_t parent, const std::string& name,
                 const std::vector<FieldDesc>& fields, size_t rows,
                 const char* data) {
  const std::string what = PathOf(parent, name);
  Handle file_type = MakeCompoundType(fields, /*file=*/true);
  Handle mem_type = MakeCompoundType(fields, /*file=*/false);
  if (!file_type.valid() || !mem_type.valid()) {
    return WriteHdf5Error(what, "building the row type");
  }
  return WriteOneDimensional(parent, name, file_type.get(), mem_type.get(),
                             rows, data);
}

Result<PackedRows> ReadRows(hid_t parent, const std::string& name,
                            const std::vector<FieldDesc>& fields) {
  const std::string what = PathOf(parent, name);
  if (GetObjectKind(parent, what) != ObjectKind::kDataset) {
    return ReadError(what + ": missing dataset");
  }
  Handle dataset(H5Dopen2(parent, name.c_str(), H5P_DEFAULT));
  if (!dataset.valid()) return ReadHdf5Error(what, "opening");
  Handle type(H5Dget_type(dataset.get()));
  Handle space(H5Dget_space(dataset.get()));
  if (!type.valid() || !space.valid()) return ReadHdf5Error(what, "type");
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class != H5T_COMPOUND) {
    return ReadError(what + ": is " + TypeClassName(type_class) +
                     ", expected a compound (table) dataset");
  }
  // A damaged type can place members outside the row; HDF5's conversion
  // would then read out of bounds, so refuse such a type up front.
  const size_t type_size = H5Tget_size(type.get());
  const int members = H5Tget_nmembers(type.get());
  if (type_size == 0 || members < 0) return ReadHdf5Error(what, "row type");
  for (int i = 0; i < members; ++i) {
    Handle member(H5Tget_member_type(type.get(), static_cast<unsigned>(i)));
    const size_t offset =
        H5Tget_member_offset(type.get(), static_cast<unsigned>(i));
    const size_t size = member.valid() ? H5Tget_size(member.get()) : 0;
    if (size == 0 || offset > type_size || size > type_size - offset) {
      return ReadError(what + ": damaged row type (field " + std::to_string(i) +
                       " lies outside the row)");
    }
  }
  for (const FieldDesc& field : fields) {
    const int index = H5Tget_member_index(type.get(), field.name.c_str());
    if (index < 0) {
      H5Eclear2(H5E_DEFAULT);
      return ReadError(what + ": missing field '" + field.name + "'");
    }
    const H5T_class_t member_class =
        H5Tget_member_class(type.get(), static_cast<unsigned>(index));
    if (member_class != FieldClass(field.type)) {
      return ReadError(what + ": field '" + field.name + "' is " +
                       TypeClassName(member_class) + ", expected " +
                       TypeClassName(FieldClass(field.type)));
    }
    if (field.type == FieldType::kString) {
      Handle member(
          H5Tget_member_type(type.get(), static_cast<unsigned>(index)));
      if (!member.valid() || H5Tis_variable_str(member.get()) != 0) {
        return ReadError(what + ": field '" + field.name +
                         "' must be a fixed-length string");
      }
    }
  }
  if (H5Sget_simple_extent_ndims(space.get()) != 1) {
    return ReadError(what + ": expected a 1-D dataset");
  }
  hsize_t dims[1] = {0};
  if (H5Sget_simple_extent_dims(space.get(), dims, nullptr) < 0) {
    return ReadHdf5Error(what, "shape");
  }
  Handle mem_type = MakeCompoundType(fields, /*file=*/false);
  if (!mem_type.valid()) return ReadHdf5Error(what, "building the row type");
  PackedRows packed;
  packed.rows = static_cast<size_t>(dims[0]);
  packed.bytes.assign(packed.rows * RowSize(fields), '\0');
  if (packed.rows > 0 &&
      H5Dread(dataset.get(), mem_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT,
              packed.bytes.data()) < 0) {
    return ReadHdf5Error(what,
                         "reading " + std::to_string(packed.rows) + " rows");
  }
  return packed;
}

}  // namespace adse::runfile::internal
