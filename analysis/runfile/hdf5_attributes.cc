// Attributes: scalar and list values, read back with their type checked.
#include <string>
#include <vector>

#include "analysis/runfile/hdf5_util_impl.h"

namespace adse::runfile::internal {
namespace {

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

Result<bool> HasAttr(hid_t loc, const std::string& name) {
  const htri_t exists = H5Aexists(loc, name.c_str());
  if (exists < 0) return ReadHdf5Error(PathOf(loc, ""), "attribute " + name);
  return exists > 0;
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
}  // namespace adse::runfile::internal
