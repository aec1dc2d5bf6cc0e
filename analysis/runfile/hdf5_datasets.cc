// Datasets: a single string, 1-D columns and packed compound rows, all
// chunked, shuffled, deflated and checksummed.
#include <algorithm>
#include <string>
#include <vector>

#include "analysis/runfile/hdf5_util_impl.h"

namespace adse::runfile::internal {
namespace {

// Chunks of at most this many rows (and bytes): small enough for HDF5's
// default 1 MiB chunk cache, big enough that per-chunk overhead vanishes.
constexpr size_t kMaxChunkRows = 4096;
constexpr size_t kMaxChunkBytes = 512 * 1024;
constexpr unsigned kDeflateLevel = 4;

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
}  // namespace

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
  PackedRows packed;
  for (const FieldDesc& field : fields) {
    const int index = H5Tget_member_index(type.get(), field.name.c_str());
    if (index < 0) {
      H5Eclear2(H5E_DEFAULT);
      if (field.optional) continue;
      return ReadError(what + ": missing field '" + field.name + "'");
    }
    packed.fields.push_back(field);
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
  Handle mem_type = MakeCompoundType(packed.fields, /*file=*/false);
  if (!mem_type.valid()) return ReadHdf5Error(what, "building the row type");
  packed.rows = static_cast<size_t>(dims[0]);
  packed.bytes.assign(packed.rows * RowSize(packed.fields), '\0');
  if (packed.rows > 0 &&
      H5Dread(dataset.get(), mem_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT,
              packed.bytes.data()) < 0) {
    return ReadHdf5Error(what,
                         "reading " + std::to_string(packed.rows) + " rows");
  }
  return packed;
}

}  // namespace adse::runfile::internal
