// The campaign index (campaign.h5): one column dataset per field, so h5py
// gives numpy arrays and pandas a DataFrame with no adse code. Layout:
// results-schema/campaign.schema.json (human guide: results-schema/README.md).
#include "analysis/runfile/campaign_file.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <new>
#include <set>
#include <utility>

#include "analysis/runfile/hdf5_util_impl.h"

namespace adse::runfile {
namespace {

using internal::Assign;
using internal::Handle;
using internal::ReadColumn;
using internal::WriteColumn;

constexpr char kKind[] = "adse-campaign";
// Attribute of /evaluations/point and /evaluations/metrics: the column
// names in CampaignIndex order (h5py lists datasets by name instead).
constexpr char kNamesAttr[] = "names";
// Separator of /iterations/content_keys.
constexpr char kKeySeparator = ',';

// ---------------------------------------------------------------------------
// Validation before anything touches the disk.

bool HasNul(const std::string& text) {
  return text.find('\0') != std::string::npos;
}

// Column names become HDF5 link names: no '/', not "." and not empty.
Status CheckNames(const char* what, const std::vector<std::string>& names) {
  std::set<std::string> seen;
  for (const std::string& name : names) {
    if (name.empty() || name == "." || name.find('/') != std::string::npos ||
        HasNul(name)) {
      return Status::InvalidArgument(std::string(what) + " name '" + name +
                                     "' cannot be an HDF5 dataset name "
                                     "(empty, '.', or holds '/' or NUL)");
    }
    if (!seen.insert(name).second) {
      return Status::InvalidArgument(std::string(what) + " name '" + name +
                                     "' is listed twice");
    }
  }
  return Status::Ok();
}

// Every entry of a row's map must have a column, or it would be lost.
Status CheckKeys(const char* what, size_t row,
                 const std::map<std::string, double>& values,
                 const std::set<std::string>& columns) {
  for (const auto& entry : values) {
    if (columns.count(entry.first) == 0) {
      return Status::InvalidArgument(
          "evaluation " + std::to_string(row) + ": " + what + " '" +
          entry.first + "' is not in CampaignIndex::" + what + "s");
    }
  }
  return Status::Ok();
}

Status Validate(const CampaignIndex& index) {
  ADSE_RETURN_IF_ERROR(CheckNames("parameter", index.parameters));
  ADSE_RETURN_IF_ERROR(CheckNames("metric", index.metrics));
  for (const std::string* text :
       {&index.scenario_name, &index.scenario_text, &index.strategy,
        &index.isolation, &index.adse_version}) {
    if (HasNul(*text)) {
      return Status::InvalidArgument("campaign attribute holds a NUL byte");
    }
  }
  const std::set<std::string> parameters(index.parameters.begin(),
                                         index.parameters.end());
  const std::set<std::string> metrics(index.metrics.begin(),
                                      index.metrics.end());
  for (size_t i = 0; i < index.evaluations.size(); ++i) {
    const EvaluationRow& row = index.evaluations[i];
    ADSE_RETURN_IF_ERROR(CheckKeys("parameter", i, row.point, parameters));
    ADSE_RETURN_IF_ERROR(CheckKeys("metric", i, row.metrics, metrics));
    for (const EvaluationRow& replica : row.replicas) {
      ADSE_RETURN_IF_ERROR(
          CheckKeys("parameter", i, replica.point, parameters));
      ADSE_RETURN_IF_ERROR(CheckKeys("metric", i, replica.metrics, metrics));
      if (replica.index != row.index || !replica.replicas.empty()) {
        return Status::InvalidArgument(
            "evaluation " + std::to_string(i) +
            ": a replica has another index or replicas of its own");
      }
    }
  }
  for (size_t i = 0; i < index.iterations.size(); ++i) {
    for (const std::string& key : index.iterations[i].content_keys) {
      if (key.empty() || key.find(kKeySeparator) != std::string::npos) {
        return Status::InvalidArgument("iteration " + std::to_string(i) +
                                       ": content key '" + key +
                                       "' is empty or holds a ','");
      }
    }
  }
  // Strings with NUL inside are refused by WriteColumn, naming the dataset.
  return Status::Ok();
}

// ---------------------------------------------------------------------------
// Writing.

template <typename T, typename Row, typename Get>
std::vector<T> Gather(const std::vector<Row>& rows, Get get) {
  std::vector<T> out;
  out.reserve(rows.size());
  for (const Row& row : rows) out.push_back(static_cast<T>(get(row)));
  return out;
}

// One float64 column per name, NaN where a row's map lacks it, plus the
// names in order as an attribute.
Status WriteNumberGroup(hid_t parent, const char* group_name,
                        const std::vector<std::string>& names,
                        const std::vector<EvaluationRow>& rows,
                        std::map<std::string, double> EvaluationRow::*member) {
  Result<Handle> group = internal::CreateGroup(parent, group_name);
  if (!group.ok()) return group.status();
  ADSE_RETURN_IF_ERROR(
      internal::WriteStringListAttr(group->get(), kNamesAttr, names));
  std::vector<double> column(rows.size());
  for (const std::string& name : names) {
    for (size_t i = 0; i < rows.size(); ++i) {
      const auto& values = rows[i].*member;
      const auto found = values.find(name);
      column[i] = found != values.end()
                      ? found->second
                      : std::numeric_limits<double>::quiet_NaN();
    }
    ADSE_RETURN_IF_ERROR(WriteColumn(group->get(), name, column));
  }
  return Status::Ok();
}

std::string JoinKeys(const std::vector<std::string>& keys) {
  std::string out;
  for (size_t i = 0; i < keys.size(); ++i) {
    if (i > 0) out += kKeySeparator;
    out += keys[i];
  }
  return out;
}

// /evaluations, or /replicas (the same columns, `replica` instead of
// `replicas` and `unstable`).
Status WriteEvaluationTable(hid_t file, const char* name,
                            const CampaignIndex& index,
                            const std::vector<EvaluationRow>& rows) {
  const bool replica_table = std::string(name) == "replicas";
  Result<Handle> group = internal::CreateGroup(file, name);
  if (!group.ok()) return group.status();
  const hid_t g = group->get();
  using Row = EvaluationRow;
  ADSE_RETURN_IF_ERROR(WriteColumn(
      g, "index", Gather<int64_t>(rows, [](const Row& r) { return r.index; })));
  ADSE_RETURN_IF_ERROR(WriteColumn(
      g, "iteration",
      Gather<int64_t>(rows, [](const Row& r) { return r.iteration; })));
  ADSE_RETURN_IF_ERROR(WriteColumn(
      g, "content_key",
      Gather<std::string>(rows, [](const Row& r) { return r.content_key; })));
  ADSE_RETURN_IF_ERROR(WriteColumn(
      g, "status",
      Gather<std::string>(rows, [](const Row& r) { return r.status; })));
  ADSE_RETURN_IF_ERROR(WriteColumn(
      g, "reason",
      Gather<std::string>(rows, [](const Row& r) { return r.reason; })));
  ADSE_RETURN_IF_ERROR(WriteColumn(
      g, "source",
      Gather<std::string>(rows, [](const Row& r) { return r.source; })));
  ADSE_RETURN_IF_ERROR(WriteColumn(
      g, "attempts",
      Gather<int64_t>(rows, [](const Row& r) { return r.attempts; })));
  ADSE_RETURN_IF_ERROR(
      WriteColumn(g, "wall_s",
                  Gather<double>(rows, [](const Row& r) { return r.wall_s; })));
  ADSE_RETURN_IF_ERROR(WriteColumn(
      g, "feasible",
      Gather<uint8_t>(rows, [](const Row& r) { return r.feasible ? 1 : 0; })));
  ADSE_RETURN_IF_ERROR(WriteColumn(
      g, "seed", Gather<uint64_t>(rows, [](const Row& r) { return r.seed; })));
  ADSE_RETURN_IF_ERROR(WriteColumn(g, "bottlenecks_json",
                                   Gather<std::string>(rows, [](const Row& r) {
                                     return r.bottlenecks_json;
                                   })));
  ADSE_RETURN_IF_ERROR(WriteColumn(
      g, "task_case",
      Gather<int64_t>(rows, [](const Row& r) { return r.task_case; })));
  if (replica_table) {
    ADSE_RETURN_IF_ERROR(WriteColumn(
        g, "replica",
        Gather<int64_t>(rows, [](const Row& r) { return r.replica; })));
  } else {
    ADSE_RETURN_IF_ERROR(
        WriteColumn(g, "replicas", Gather<int64_t>(rows, [](const Row& r) {
                      return std::max<size_t>(1, r.replicas.size());
                    })));
    ADSE_RETURN_IF_ERROR(
        WriteColumn(g, "unstable", Gather<uint8_t>(rows, [](const Row& r) {
                      return r.unstable ? 1 : 0;
                    })));
  }
  ADSE_RETURN_IF_ERROR(
      WriteNumberGroup(g, "point", index.parameters, rows, &Row::point));
  return WriteNumberGroup(g, "metrics", index.metrics, rows, &Row::metrics);
}

Status WriteContents(hid_t file, const CampaignIndex& index) {
  using internal::WriteStringAttr;
  ADSE_RETURN_IF_ERROR(
      internal::WriteI32Attr(file, "schema_version", kCampaignSchemaVersion));
  ADSE_RETURN_IF_ERROR(WriteStringAttr(file, "kind", kKind));
  ADSE_RETURN_IF_ERROR(
      WriteStringAttr(file, "scenario_name", index.scenario_name));
  ADSE_RETURN_IF_ERROR(
      WriteStringAttr(file, "scenario_text", index.scenario_text));
  ADSE_RETURN_IF_ERROR(WriteStringAttr(file, "strategy", index.strategy));
  ADSE_RETURN_IF_ERROR(
      internal::WriteU64Attr(file, "exploration_seed", index.exploration_seed));
  ADSE_RETURN_IF_ERROR(internal::WriteI64Attr(file, "budget", index.budget));
  ADSE_RETURN_IF_ERROR(WriteStringAttr(file, "isolation", index.isolation));
  ADSE_RETURN_IF_ERROR(
      WriteStringAttr(file, "adse_version", index.adse_version));

  ADSE_RETURN_IF_ERROR(
      WriteEvaluationTable(file, "evaluations", index, index.evaluations));
  std::vector<EvaluationRow> replicas;
  for (const EvaluationRow& row : index.evaluations) {
    replicas.insert(replicas.end(), row.replicas.begin(), row.replicas.end());
  }
  ADSE_RETURN_IF_ERROR(WriteEvaluationTable(file, "replicas", index, replicas));
  {
    const auto& rows = index.iterations;
    Result<Handle> group = internal::CreateGroup(file, "iterations");
    if (!group.ok()) return group.status();
    const hid_t g = group->get();
    using Row = IterationRow;
    ADSE_RETURN_IF_ERROR(WriteColumn(
        g, "iteration",
        Gather<int64_t>(rows, [](const Row& r) { return r.iteration; })));
    ADSE_RETURN_IF_ERROR(WriteColumn(
        g, "strategy",
        Gather<std::string>(rows, [](const Row& r) { return r.strategy; })));
    ADSE_RETURN_IF_ERROR(WriteColumn(
        g, "rationale",
        Gather<std::string>(rows, [](const Row& r) { return r.rationale; })));
    ADSE_RETURN_IF_ERROR(WriteColumn(
        g, "content_keys", Gather<std::string>(rows, [](const Row& r) {
          return JoinKeys(r.content_keys);
        })));
  }
  {
    const auto& rows = index.llm_exchanges;
    Result<Handle> group = internal::CreateGroup(file, "llm_exchanges");
    if (!group.ok()) return group.status();
    const hid_t g = group->get();
    using Row = LlmExchangeRow;
    auto ints = [&](const char* name, int64_t Row::*member) {
      return WriteColumn(g, name, Gather<int64_t>(rows, [&](const Row& r) {
                           return r.*member;
                         }));
    };
    auto strings = [&](const char* name, std::string Row::*member) {
      return WriteColumn(g, name, Gather<std::string>(rows, [&](const Row& r) {
                           return r.*member;
                         }));
    };
    ADSE_RETURN_IF_ERROR(ints("seq", &Row::seq));
    ADSE_RETURN_IF_ERROR(ints("iteration", &Row::iteration));
    ADSE_RETURN_IF_ERROR(strings("agent", &Row::agent));
    ADSE_RETURN_IF_ERROR(strings("model", &Row::model));
    ADSE_RETURN_IF_ERROR(strings("backend", &Row::backend));
    ADSE_RETURN_IF_ERROR(strings("request_sha256", &Row::request_sha256));
    ADSE_RETURN_IF_ERROR(strings("prompt", &Row::prompt));
    ADSE_RETURN_IF_ERROR(strings("image_sha256", &Row::image_sha256));
    ADSE_RETURN_IF_ERROR(WriteColumn(
        g, "ok",
        Gather<uint8_t>(rows, [](const Row& r) { return r.ok ? 1 : 0; })));
    ADSE_RETURN_IF_ERROR(strings("answer", &Row::answer));
    ADSE_RETURN_IF_ERROR(strings("error", &Row::error));
    ADSE_RETURN_IF_ERROR(ints("prompt_tokens", &Row::prompt_tokens));
    ADSE_RETURN_IF_ERROR(ints("completion_tokens", &Row::completion_tokens));
    ADSE_RETURN_IF_ERROR(WriteColumn(
        g, "latency_s",
        Gather<double>(rows, [](const Row& r) { return r.latency_s; })));
    ADSE_RETURN_IF_ERROR(ints("attempts", &Row::attempts));
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------
// Reading. Failures name the HDF5 object; ReadFileContents prefixes the file
// and makes them Corruption.

// Reads column `name` of the group at `group_path` and checks it has `rows`
// rows (the length of the group's first column).
template <typename T>
Status ReadSized(hid_t group, const std::string& group_path,
                 const std::string& name, size_t rows, std::vector<T>* out) {
  ADSE_RETURN_IF_ERROR(ReadColumn(group, name, out));
  if (out->size() != rows) {
    return Status::Corruption(group_path + "/" + name + ": " +
                              std::to_string(out->size()) + " rows, expected " +
                              std::to_string(rows) +
                              " like the other columns of " + group_path);
  }
  return Status::Ok();
}

// Reads column `name` (of T) into `member` of each row; `rows` is sized by
// the group's first column already.
template <typename T, typename Row, typename Member>
Status ReadMember(hid_t group, const std::string& group_path,
                  const std::string& name, std::vector<Row>* rows,
                  Member Row::*member) {
  std::vector<T> column;
  ADSE_RETURN_IF_ERROR(
      ReadSized(group, group_path, name, rows->size(), &column));
  for (size_t i = 0; i < rows->size(); ++i) {
    (*rows)[i].*member = static_cast<Member>(std::move(column[i]));
  }
  return Status::Ok();
}

// The float64 columns of /evaluations/point or /evaluations/metrics into the
// rows' maps (NaN left out), their order from the `names` attribute.
Status ReadNumberGroup(hid_t file, const std::string& path,
                       std::vector<std::string>* names,
                       std::vector<EvaluationRow>* rows,
                       std::map<std::string, double> EvaluationRow::*member) {
  Result<Handle> group = internal::OpenGroup(file, path);
  if (!group.ok()) return group.status();
  ADSE_RETURN_IF_ERROR(
      Assign(internal::ReadStringListAttr(group->get(), kNamesAttr), names));
  std::set<std::string> seen;
  for (const std::string& name : *names) {
    if (name.empty() || !seen.insert(name).second) {
      return Status::Corruption(path + ": attribute '" + kNamesAttr +
                                "' has an empty or repeated name '" + name +
                                "'");
    }
  }
  std::vector<double> column;
  for (const std::string& name : *names) {
    ADSE_RETURN_IF_ERROR(
        ReadSized(group->get(), path, name, rows->size(), &column));
    for (size_t i = 0; i < rows->size(); ++i) {
      if (!std::isnan(column[i])) ((*rows)[i].*member)[name] = column[i];
    }
  }
  return Status::Ok();
}

std::vector<std::string> SplitKeys(const std::string& joined) {
  std::vector<std::string> keys;
  if (joined.empty()) return keys;
  size_t start = 0;
  while (true) {
    const size_t end = joined.find(kKeySeparator, start);
    keys.push_back(joined.substr(start, end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return keys;
}

// The rows of /evaluations or /replicas (see WriteEvaluationTable); the
// column names of point/ and metrics/ go to `index` (of /evaluations) or
// are checked against it (of /replicas).
Status ReadEvaluationTable(hid_t file, const std::string& path,
                           CampaignIndex* index,
                           std::vector<EvaluationRow>* rows) {
  const bool replica_table = path == "/replicas";
  Result<Handle> group = internal::OpenGroup(file, path);
  if (!group.ok()) return group.status();
  const hid_t g = group->get();
  std::vector<int64_t> numbers;
  ADSE_RETURN_IF_ERROR(ReadColumn(g, "index", &numbers));
  const size_t n = numbers.size();
  rows->assign(n, EvaluationRow{});
  for (size_t i = 0; i < n; ++i) (*rows)[i].index = numbers[i];

  using Row = EvaluationRow;
  ADSE_RETURN_IF_ERROR(
      ReadMember<int64_t>(g, path, "iteration", rows, &Row::iteration));
  ADSE_RETURN_IF_ERROR(
      ReadMember<std::string>(g, path, "content_key", rows, &Row::content_key));
  ADSE_RETURN_IF_ERROR(
      ReadMember<std::string>(g, path, "status", rows, &Row::status));
  ADSE_RETURN_IF_ERROR(
      ReadMember<std::string>(g, path, "reason", rows, &Row::reason));
  ADSE_RETURN_IF_ERROR(
      ReadMember<std::string>(g, path, "source", rows, &Row::source));
  ADSE_RETURN_IF_ERROR(
      ReadMember<int64_t>(g, path, "attempts", rows, &Row::attempts));
  ADSE_RETURN_IF_ERROR(ReadMember<std::string>(g, path, "bottlenecks_json",
                                               rows, &Row::bottlenecks_json));
  ADSE_RETURN_IF_ERROR(
      ReadMember<double>(g, path, "wall_s", rows, &Row::wall_s));
  ADSE_RETURN_IF_ERROR(
      ReadMember<uint8_t>(g, path, "feasible", rows, &Row::feasible));
  ADSE_RETURN_IF_ERROR(ReadMember<uint64_t>(g, path, "seed", rows, &Row::seed));
  // Indexes written before task.cases existed lack the column.
  if (internal::GetObjectKind(file, path + "/task_case") !=
      internal::ObjectKind::kMissing) {
    ADSE_RETURN_IF_ERROR(
        ReadMember<int64_t>(g, path, "task_case", rows, &Row::task_case));
  }
  if (replica_table) {
    ADSE_RETURN_IF_ERROR(
        ReadMember<int64_t>(g, path, "replica", rows, &Row::replica));
  } else if (internal::GetObjectKind(file, path + "/unstable") !=
             internal::ObjectKind::kMissing) {
    // Indexes written before replicas existed lack the column.
    ADSE_RETURN_IF_ERROR(
        ReadMember<uint8_t>(g, path, "unstable", rows, &Row::unstable));
  }
  std::vector<std::string> parameters, metrics;
  ADSE_RETURN_IF_ERROR(ReadNumberGroup(file, path + "/point", &parameters, rows,
                                       &EvaluationRow::point));
  ADSE_RETURN_IF_ERROR(ReadNumberGroup(file, path + "/metrics", &metrics, rows,
                                       &EvaluationRow::metrics));
  if (!replica_table) {
    index->parameters = std::move(parameters);
    index->metrics = std::move(metrics);
  }
  return Status::Ok();
}

Status ReadContents(hid_t file, CampaignIndex* index) {
  using internal::ReadStringAttr;
  // `kind` first: a run file (same schema_version) is told apart clearly.
  Result<std::string> kind = ReadStringAttr(file, "kind");
  if (!kind.ok()) {
    return Status::Corruption(kind.status().message() +
                              " (not an adse campaign index)");
  }
  if (*kind != kKind) {
    return Status::Corruption("/: attribute 'kind' is '" + *kind +
                              "', expected '" + kKind + "'");
  }
  Result<int64_t> version = internal::ReadI64Attr(file, "schema_version");
  if (!version.ok()) return version.status();
  if (*version != kCampaignSchemaVersion) {
    return Status::Corruption("/: schema_version " + std::to_string(*version) +
                              " is not the supported " +
                              std::to_string(kCampaignSchemaVersion));
  }
  ADSE_RETURN_IF_ERROR(
      Assign(ReadStringAttr(file, "scenario_name"), &index->scenario_name));
  ADSE_RETURN_IF_ERROR(
      Assign(ReadStringAttr(file, "scenario_text"), &index->scenario_text));
  ADSE_RETURN_IF_ERROR(
      Assign(ReadStringAttr(file, "strategy"), &index->strategy));
  ADSE_RETURN_IF_ERROR(Assign(internal::ReadU64Attr(file, "exploration_seed"),
                              &index->exploration_seed));
  ADSE_RETURN_IF_ERROR(
      Assign(internal::ReadI64Attr(file, "budget"), &index->budget));
  ADSE_RETURN_IF_ERROR(
      Assign(ReadStringAttr(file, "isolation"), &index->isolation));
  ADSE_RETURN_IF_ERROR(
      Assign(ReadStringAttr(file, "adse_version"), &index->adse_version));

  ADSE_RETURN_IF_ERROR(
      ReadEvaluationTable(file, "/evaluations", index, &index->evaluations));
  // Indexes written before replicas existed have no replica table.
  if (internal::GetObjectKind(file, "/replicas") !=
      internal::ObjectKind::kMissing) {
    std::vector<EvaluationRow> replicas;
    ADSE_RETURN_IF_ERROR(
        ReadEvaluationTable(file, "/replicas", index, &replicas));
    std::map<int64_t, size_t> position;
    for (size_t i = 0; i < index->evaluations.size(); ++i) {
      position[index->evaluations[i].index] = i;
    }
    for (EvaluationRow& replica : replicas) {
      const auto found = position.find(replica.index);
      if (found == position.end()) {
        return Status::Corruption("/replicas/index: replica of evaluation " +
                                  std::to_string(replica.index) +
                                  ", which /evaluations lacks");
      }
      index->evaluations[found->second].replicas.push_back(std::move(replica));
    }
  }
  {
    const std::string path = "/iterations";
    Result<Handle> group = internal::OpenGroup(file, path);
    if (!group.ok()) return group.status();
    const hid_t g = group->get();
    std::vector<int64_t> numbers;
    ADSE_RETURN_IF_ERROR(ReadColumn(g, "iteration", &numbers));
    const size_t n = numbers.size();
    auto& rows = index->iterations;
    rows.assign(n, IterationRow{});
    for (size_t i = 0; i < n; ++i) rows[i].iteration = numbers[i];
    std::vector<std::string> column;
    ADSE_RETURN_IF_ERROR(ReadSized(g, path, "strategy", n, &column));
    for (size_t i = 0; i < n; ++i) rows[i].strategy = std::move(column[i]);
    ADSE_RETURN_IF_ERROR(ReadSized(g, path, "rationale", n, &column));
    for (size_t i = 0; i < n; ++i) rows[i].rationale = std::move(column[i]);
    ADSE_RETURN_IF_ERROR(ReadSized(g, path, "content_keys", n, &column));
    for (size_t i = 0; i < n; ++i) rows[i].content_keys = SplitKeys(column[i]);
  }
  // Indexes written before LLM campaigns existed have no exchanges group.
  if (internal::GetObjectKind(file, "/llm_exchanges") !=
      internal::ObjectKind::kMissing) {
    const std::string path = "/llm_exchanges";
    Result<Handle> group = internal::OpenGroup(file, path);
    if (!group.ok()) return group.status();
    const hid_t g = group->get();
    using Row = LlmExchangeRow;
    std::vector<int64_t> numbers;
    ADSE_RETURN_IF_ERROR(ReadColumn(g, "seq", &numbers));
    const size_t n = numbers.size();
    auto& rows = index->llm_exchanges;
    rows.assign(n, Row{});
    for (size_t i = 0; i < n; ++i) rows[i].seq = numbers[i];
    for (const auto& [name, member] :
         {std::pair{"iteration", &Row::iteration},
          {"prompt_tokens", &Row::prompt_tokens},
          {"completion_tokens", &Row::completion_tokens},
          {"attempts", &Row::attempts}}) {
      ADSE_RETURN_IF_ERROR(ReadMember<int64_t>(g, path, name, &rows, member));
    }
    for (const auto& [name, member] : {std::pair{"agent", &Row::agent},
                                       {"model", &Row::model},
                                       {"backend", &Row::backend},
                                       {"request_sha256", &Row::request_sha256},
                                       {"prompt", &Row::prompt},
                                       {"image_sha256", &Row::image_sha256},
                                       {"answer", &Row::answer},
                                       {"error", &Row::error}}) {
      ADSE_RETURN_IF_ERROR(
          ReadMember<std::string>(g, path, name, &rows, member));
    }
    ADSE_RETURN_IF_ERROR(ReadMember<uint8_t>(g, path, "ok", &rows, &Row::ok));
    ADSE_RETURN_IF_ERROR(
        ReadMember<double>(g, path, "latency_s", &rows, &Row::latency_s));
  }
  return Status::Ok();
}

}  // namespace

Status WriteCampaignIndex(const std::string& path, const CampaignIndex& index,
                          Env* env) {
  try {
    ADSE_RETURN_IF_ERROR(Validate(index));
    return internal::WriteFileAtomically(
        path, [&index](hid_t file) { return WriteContents(file, index); }, env);
  } catch (const std::bad_alloc&) {
    return Status::Internal(path +
                            ": out of memory writing the campaign index");
  } catch (const std::exception& e) {
    return Status::Internal(path + ": writing the campaign index: " + e.what());
  }
}

Result<CampaignIndex> ReadCampaignIndex(const std::string& path) {
  try {
    CampaignIndex index;
    ADSE_RETURN_IF_ERROR(internal::ReadFileContents(
        path, "a campaign index",
        [&index](hid_t file) { return ReadContents(file, &index); }));
    return index;
  } catch (const std::bad_alloc&) {
    // A damaged header can claim absurd sizes.
    return Status::Corruption(path +
                              ": out of memory reading (sizes in the "
                              "file are implausible?)");
  } catch (const std::exception& e) {
    return Status::Corruption(path +
                              ": reading the campaign index: " + e.what());
  }
}

}  // namespace adse::runfile
