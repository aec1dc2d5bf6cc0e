// Strings in HDF5: fixed-length string types, packing a list of strings
// into one buffer, and reading strings of either length back.
#include <algorithm>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "analysis/runfile/hdf5_util_impl.h"

namespace adse::runfile::internal {

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

Handle MakeFixedStringType(const std::string& value) {
  return MakeFixedStringTypeOfSize(value.size());
}

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

std::vector<char> PaddedString(const std::string& value) {
  std::vector<char> bytes(std::max<size_t>(1, value.size()), '\0');
  std::copy(value.begin(), value.end(), bytes.begin());
  return bytes;
}
Result<std::string> ReadScalarString(hid_t obj, bool is_attr,
                                     const std::string& what) {
  Result<std::vector<std::string>> one =
      ReadStrings(obj, is_attr, what, /*array=*/false);
  if (!one.ok()) return one.status();
  return std::move(one->front());
}

}  // namespace adse::runfile::internal
