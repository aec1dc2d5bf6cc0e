// CheckRunFile: validates a run file against results-schema/run.schema.json,
// driven by the JSON alone so the schema stays the single contract.
#include <algorithm>
#include <cstring>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>

#include "analysis/runfile/hdf5_util_impl.h"
#include "analysis/runfile/run_file.h"
#include "stack/base/files.h"
#include "stack/base/hash.h"

namespace adse::runfile {
namespace {

namespace fs = std::filesystem;
using internal::Handle;
using internal::ObjectKind;
using nlohmann::json;

// Schema class names mapped to HDF5 type classes.
bool ClassMatches(const std::string& schema_class, H5T_class_t actual) {
  if (schema_class == "float") return actual == H5T_FLOAT;
  if (schema_class == "int") return actual == H5T_INTEGER;
  if (schema_class == "string") return actual == H5T_STRING;
  if (schema_class == "enum") return actual == H5T_ENUM;
  if (schema_class == "compound") return actual == H5T_COMPOUND;
  return false;
}

class Checker {
 public:
  Checker(hid_t file, const json& schema, std::vector<std::string>* problems)
      : file_(file), schema_(schema), problems_(problems) {}

  void Run() {
    for (const json& attr : schema_.at("root_attributes")) CheckRootAttr(attr);
    for (const json& group : schema_.at("groups")) CheckGroup(group);
    for (const json& dataset : schema_.at("datasets")) CheckDataset(dataset);
  }

 private:
  void Problem(const std::string& path, const std::string& what) {
    problems_->push_back(path + ": " + what);
  }

  // Opens attribute `name` of `loc` and checks its class; invalid if absent
  // or of the wrong class (a problem is recorded).
  Handle OpenAttr(hid_t loc, const std::string& loc_path,
                  const std::string& name, const std::string& schema_class) {
    const htri_t exists = H5Aexists(loc, name.c_str());
    if (exists <= 0) {
      internal::TakeHdf5Error();
      Problem(loc_path, "missing attribute '" + name + "'");
      return Handle();
    }
    Handle attr(H5Aopen(loc, name.c_str(), H5P_DEFAULT));
    Handle type(attr.valid() ? H5Aget_type(attr.get()) : -1);
    if (!type.valid()) {
      Problem(loc_path, "attribute '" + name +
                            "' unreadable: " + internal::TakeHdf5Error());
      return Handle();
    }
    const H5T_class_t actual = H5Tget_class(type.get());
    if (!ClassMatches(schema_class, actual)) {
      Problem(loc_path, "attribute '" + name + "' is " +
                            internal::TypeClassName(actual) + ", expected " +
                            schema_class);
      return Handle();
    }
    return attr;
  }

  void CheckRootAttr(const json& spec) {
    const std::string name = spec.at("name").get<std::string>();
    const std::string schema_class = spec.at("class").get<std::string>();
    if (spec.value("optional", false) && H5Aexists(file_, name.c_str()) <= 0) {
      return;
    }
    Handle attr = OpenAttr(file_, "/", name, schema_class);
    if (!attr.valid()) return;
    attr.Reset();
    if (name == "schema_version") {
      const int64_t wanted = schema_.at("schema_version").get<int64_t>();
      Result<int64_t> version = internal::ReadI64Attr(file_, name);
      if (!version.ok()) {
        Problem("/", version.status().message());
      } else if (*version != wanted) {
        Problem("/", "schema_version " + std::to_string(*version) +
                         " is not compatible with schema version " +
                         std::to_string(wanted));
      }
    }
    if (spec.contains("values") && schema_class == "string") {
      Result<std::string> value = internal::ReadStringAttr(file_, name);
      if (!value.ok()) {
        Problem("/", value.status().message());
        return;
      }
      const auto& values = spec.at("values");
      if (std::find(values.begin(), values.end(), *value) == values.end()) {
        Problem("/", "attribute '" + name + "' is '" + *value +
                         "', expected one of " + values.dump());
      }
    }
  }

  void CheckGroup(const json& spec) {
    const std::string path = spec.at("path").get<std::string>();
    const ObjectKind kind = internal::GetObjectKind(file_, path);
    if (kind == ObjectKind::kMissing) {
      // Optional groups exist only in some runs (e.g. /parking).
      if (!spec.value("optional", false)) Problem(path, "missing group");
      return;
    }
    if (kind != ObjectKind::kGroup) {
      Problem(path, "is not a group");
      return;
    }
    if (!spec.contains("attribute_class") && !spec.contains("attributes") &&
        !spec.contains("column_class")) {
      return;
    }
    Handle group(H5Gopen2(file_, path.c_str(), H5P_DEFAULT));
    if (!group.valid()) {
      Problem(path, "opening: " + internal::TakeHdf5Error());
      return;
    }
    // Named attributes of the group, each of its class.
    for (const json& attr : spec.value("attributes", json::array())) {
      OpenAttr(group.get(), path, attr.at("name").get<std::string>(),
               attr.at("class").get<std::string>());
    }
    if (spec.contains("column_class")) {
      CheckColumns(group, path, spec.at("column_class").get<std::string>());
    }
    if (!spec.contains("attribute_class")) return;
    const std::string schema_class =
        spec.at("attribute_class").get<std::string>();
    Result<std::vector<std::string>> names =
        internal::ListAttributes(group.get());
    if (!names.ok()) {
      Problem(path, names.status().message());
      return;
    }
    for (const std::string& name : *names) {
      OpenAttr(group.get(), path, name, schema_class);
    }
  }

  // Every member of the group must be a column (1-D dataset) of the class.
  void CheckColumns(const Handle& group, const std::string& path,
                    const std::string& schema_class) {
    H5G_info_t info;
    if (H5Gget_info(group.get(), &info) < 0) {
      Problem(path, "listing members: " + internal::TakeHdf5Error());
      return;
    }
    for (hsize_t i = 0; i < info.nlinks; ++i) {
      const ssize_t size =
          H5Lget_name_by_idx(group.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i,
                             nullptr, 0, H5P_DEFAULT);
      if (size < 0) {
        Problem(path, "listing members: " + internal::TakeHdf5Error());
        return;
      }
      std::string name(static_cast<size_t>(size) + 1, '\0');
      H5Lget_name_by_idx(group.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i,
                         name.data(), name.size(), H5P_DEFAULT);
      name.resize(static_cast<size_t>(size));
      const std::string member = path + "/" + name;
      if (internal::GetObjectKind(file_, member) != ObjectKind::kDataset) {
        Problem(member, "is not a dataset");
        continue;
      }
      Handle dataset(H5Dopen2(file_, member.c_str(), H5P_DEFAULT));
      Handle type(dataset.valid() ? H5Dget_type(dataset.get()) : -1);
      Handle space(dataset.valid() ? H5Dget_space(dataset.get()) : -1);
      if (!type.valid() || !space.valid()) {
        Problem(member, "unreadable: " + internal::TakeHdf5Error());
        continue;
      }
      CheckColumn(member, H5Tget_class(type.get()),
                  H5Sget_simple_extent_ndims(space.get()), schema_class);
    }
  }

  // A column: 1-D, one value of `schema_class` per row.
  void CheckColumn(const std::string& path, H5T_class_t actual, int rank,
                   const std::string& schema_class) {
    if (rank != 1) Problem(path, "expected a 1-D dataset (one value per row)");
    if (!ClassMatches(schema_class, actual)) {
      Problem(path, std::string("is ") + internal::TypeClassName(actual) +
                        ", expected " + schema_class);
    }
  }

  void CheckDataset(const json& spec) {
    const std::string path = spec.at("path").get<std::string>();
    const ObjectKind kind = internal::GetObjectKind(file_, path);
    if (kind == ObjectKind::kMissing) {
      if (!spec.value("optional", false)) Problem(path, "missing dataset");
      return;
    }
    if (kind != ObjectKind::kDataset) {
      Problem(path, "is not a dataset");
      return;
    }
    Handle dataset(H5Dopen2(file_, path.c_str(), H5P_DEFAULT));
    Handle type(dataset.valid() ? H5Dget_type(dataset.get()) : -1);
    Handle space(dataset.valid() ? H5Dget_space(dataset.get()) : -1);
    if (!type.valid() || !space.valid()) {
      Problem(path, "unreadable: " + internal::TakeHdf5Error());
      return;
    }
    const H5T_class_t actual = H5Tget_class(type.get());
    const int rank = H5Sget_simple_extent_ndims(space.get());
    const std::string shape = spec.value("shape", std::string("rows"));
    if (shape == "column") {
      CheckColumn(path, actual, rank, spec.at("class").get<std::string>());
      return;
    }
    if (shape == "scalar") {
      if (rank != 0) Problem(path, "expected a scalar dataset");
      const std::string schema_class = spec.at("class").get<std::string>();
      if (!ClassMatches(schema_class, actual)) {
        Problem(path, std::string("is ") + internal::TypeClassName(actual) +
                          ", expected " + schema_class);
        return;
      }
      if (spec.contains("sha256_attribute")) CheckSha256(path, spec);
      return;
    }
    if (rank != 1) Problem(path, "expected a 1-D dataset (one row per entry)");
    if (actual != H5T_COMPOUND) {
      Problem(path, std::string("is ") + internal::TypeClassName(actual) +
                        ", expected a compound (table) dataset");
      return;
    }
    for (const json& field : spec.at("fields")) CheckField(path, type, field);
  }

  // A string dataset whose sha256 a root attribute records (when not
  // empty): the text itself carries no HDF5 checksum.
  void CheckSha256(const std::string& path, const json& spec) {
    const std::string attr = spec.at("sha256_attribute").get<std::string>();
    Result<std::string> hash = internal::ReadStringAttr(file_, attr);
    if (!hash.ok() || hash->empty()) return;  // reported with the attributes
    const auto slash = path.rfind('/');
    Handle parent(H5Oopen(file_,
                          path.substr(0, std::max<size_t>(slash, 1)).c_str(),
                          H5P_DEFAULT));
    Result<std::string> text =
        parent.valid()
            ? internal::ReadStringDataset(parent.get(), path.substr(slash + 1))
            : Result<std::string>(
                  Status::Corruption(internal::TakeHdf5Error()));
    if (!text.ok()) {
      Problem(path, text.status().message());
    } else if (Sha256Hex(*text) != *hash) {
      Problem(path, "text does not match attribute '" + attr + "' (damaged)");
    }
  }

  void CheckField(const std::string& path, const Handle& type,
                  const json& field) {
    const std::string name = field.at("name").get<std::string>();
    const std::string schema_class = field.at("class").get<std::string>();
    const int index = H5Tget_member_index(type.get(), name.c_str());
    if (index < 0) {
      internal::TakeHdf5Error();
      if (!field.value("optional", false))
        Problem(path, "missing field '" + name + "'");
      return;
    }
    Handle member(H5Tget_member_type(type.get(), static_cast<unsigned>(index)));
    if (!member.valid()) {
      Problem(path,
              "field '" + name + "' unreadable: " + internal::TakeHdf5Error());
      return;
    }
    const H5T_class_t actual = H5Tget_class(member.get());
    if (!ClassMatches(schema_class, actual)) {
      Problem(path, "field '" + name + "' is " +
                        internal::TypeClassName(actual) + ", expected " +
                        schema_class);
      return;
    }
    if (schema_class == "string" && field.contains("size") &&
        H5Tis_variable_str(member.get()) != 0) {
      Problem(path, "field '" + name + "' must be a fixed-length string");
    }
    if (schema_class == "enum" && field.contains("values")) {
      CheckEnum(path, name, member, field.at("values"), /*required=*/true);
    }
    // Codes added later: older files lack them; a file that has one must
    // have it with its value.
    if (schema_class == "enum" && field.contains("added_values")) {
      CheckEnum(path, name, member, field.at("added_values"),
                /*required=*/false);
    }
  }

  // Every documented code must exist in the file's enum with its value
  // (unless not `required`: then only its value is checked).
  void CheckEnum(const std::string& path, const std::string& field,
                 const Handle& member, const json& values, bool required) {
    Handle base(H5Tget_super(member.get()));
    const size_t size = H5Tget_size(member.get());
    for (const auto& [code_name, code] : values.items()) {
      unsigned char raw[16] = {};
      if (!base.valid() || size > 8 ||
          H5Tenum_valueof(member.get(), code_name.c_str(), raw) < 0 ||
          H5Tconvert(base.get(), H5T_NATIVE_INT64, 1, raw, nullptr,
                     H5P_DEFAULT) < 0) {
        internal::TakeHdf5Error();
        if (required) {
          Problem(path,
                  "field '" + field + "' lacks enum code '" + code_name + "'");
        }
        continue;
      }
      int64_t value = 0;
      std::memcpy(&value, raw, sizeof(value));
      if (value != code.get<int64_t>()) {
        Problem(path, "field '" + field + "' enum code '" + code_name +
                          "' is " + std::to_string(value) + ", expected " +
                          std::to_string(code.get<int64_t>()));
      }
    }
  }

  hid_t file_;
  const json& schema_;
  std::vector<std::string>* problems_;
};

Result<std::shared_ptr<const json>> ParseSchema(const std::string& schema_path,
                                                const std::string& text) {
  json schema = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (schema.is_discarded() || !schema.is_object()) {
    return Status::Corruption(schema_path + ": not valid JSON");
  }
  for (const char* key :
       {"schema_version", "root_attributes", "groups", "datasets"}) {
    if (!schema.contains(key)) {
      return Status::Corruption(schema_path + ": lacks '" + key + "'");
    }
  }
  return std::make_shared<const json>(std::move(schema));
}

// Parsing the schema costs more than checking a small run file, and callers
// check many files against one schema (a campaign's runs, the fuzzer), so
// the last schema parsed is kept while its path and text stay the same.
Result<std::shared_ptr<const json>> LoadSchema(const std::string& schema_path) {
  Result<std::string> text = ReadFile(schema_path);
  if (!text.ok()) return text.status().WithContext("loading the run schema");
  static std::mutex mutex;
  static std::string cached_path;
  static std::string cached_text;
  static std::shared_ptr<const json> cached;
  std::lock_guard<std::mutex> lock(mutex);
  if (cached == nullptr || cached_path != schema_path || cached_text != *text) {
    Result<std::shared_ptr<const json>> parsed =
        ParseSchema(schema_path, *text);
    if (!parsed.ok()) return parsed.status();
    cached = *parsed;
    cached_path = schema_path;
    cached_text = std::move(*text);
  }
  return cached;
}

Status CheckImpl(const std::string& path, const std::string& schema_path,
                 std::vector<std::string>* problems) {
  Result<std::shared_ptr<const json>> schema = LoadSchema(schema_path);
  if (!schema.ok()) return schema.status();
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::NotFound(path + ": no such file");

  std::vector<std::string> found;
  {
    internal::Hdf5Session session;
    const htri_t is_hdf5 = internal::IsHdf5File(path);
    Status heaps;
    if (is_hdf5 <= 0) {
      found.push_back("/: not an HDF5 file");
    } else if (heaps = internal::CheckGlobalHeaps(path); !heaps.ok()) {
      found.push_back("/: " + heaps.message());
    } else {
      Handle fapl = internal::MakeFileAccessProps();
      Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()));
      if (!file.valid()) {
        found.push_back("/: cannot open (truncated or damaged?): " +
                        internal::TakeHdf5Error());
      } else {
        try {
          Checker(file.get(), **schema, &found).Run();
        } catch (const json::exception& e) {
          return Status::Corruption(schema_path +
                                    ": malformed schema: " + e.what());
        }
      }
    }
  }
  if (problems != nullptr) {
    problems->insert(problems->end(), found.begin(), found.end());
  }
  if (found.empty()) return Status::Ok();
  return Status::Corruption(path + ": " + std::to_string(found.size()) +
                            " problem(s) against " + schema_path +
                            "; first: " + found.front());
}

}  // namespace

std::string SchemaPath() {
  return std::string(ADSE_SCHEMA_DIR) + "/run.schema.json";
}

Status CheckRunFile(const std::string& path,
                    std::vector<std::string>* problems) {
  return CheckRunFile(path, SchemaPath(), problems);
}

Status CheckRunFile(const std::string& path, const std::string& schema_path,
                    std::vector<std::string>* problems) {
  try {
    return CheckImpl(path, schema_path, problems);
  } catch (const std::exception& e) {
    return Status::Internal(path + ": checking the run file: " + e.what());
  }
}

}  // namespace adse::runfile
