// The arrays a cast answers in, for a blob's hits (t, triangle, uv) and a
// scene's (the instance besides): one hit a ray in the rays' shape, written
// into new arrays or the caller's `out=`; or every hit, compact rows
// (found, offsets and the hits' arrays) gathered from a cast's chunks.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <type_traits>
#include <vector>

#include "meshcast/ray.h"
#include "meshcast/scene.h"
#include "python/src/arrays.h"
#include "python/src/cast.h"

namespace meshcast::python {

template <class Record>
constexpr bool kHasInstance = std::is_same_v<Record, SceneHit>;

// The hit arrays of one hit a ray: write() runs without the GIL.
template <class Record>
class OneHitAnswer {
 public:
  OneHitAnswer(const py::object& out, const std::vector<py::ssize_t>& shape, bool uv) {
    check_out_keys(out, kHasInstance<Record>, uv);
    t_ = answer_array<float>(out, "t", shape);
    triangle_ = answer_array<uint32_t>(out, "triangle", shape);
    t_out_ = t_.mutable_data();
    triangle_out_ = triangle_.mutable_data();
    if constexpr (kHasInstance<Record>) {
      instance_ = answer_array<uint32_t>(out, "instance", shape);
      instance_out_ = instance_.mutable_data();
    }
    if (uv) {
      std::vector<py::ssize_t> shape2 = shape;
      shape2.push_back(2);
      uv_ = answer_array<float>(out, "uv", shape2);
      uv_out_ = uv_.mutable_data();
    }
  }
  void write(size_t i, const Record& h) const {
    t_out_[i] = h.t;
    triangle_out_[i] = h.triangle;
    if constexpr (kHasInstance<Record>) instance_out_[i] = h.instance;
    if (uv_out_) uv_out_[2 * i] = h.u, uv_out_[2 * i + 1] = h.v;
  }
  py::dict dict() const {
    py::dict d;
    d["t"] = t_;
    if constexpr (kHasInstance<Record>) d["instance"] = instance_;
    d["triangle"] = triangle_;
    if (uv_out_) d["uv"] = uv_;
    return d;
  }

 private:
  py::array_t<float> t_, uv_;
  py::array_t<uint32_t> triangle_, instance_;
  float* t_out_ = nullptr;
  float* uv_out_ = nullptr;
  uint32_t* triangle_out_ = nullptr;
  uint32_t* instance_out_ = nullptr;
};

// Every hit: "found" (N,), "offsets" (N + 1,), then "t", ["instance"],
// "triangle", ["uv"] of the kept hits. Called with the GIL; gathers
// without it.
template <class Target>
py::dict all_hits_answer(const AllHits<Target>& all, size_t rays, bool uv) {
  using Record = typename Target::Record;
  const py::ssize_t n = py::ssize_t(rays), h = py::ssize_t(all.hits());
  py::array_t<uint32_t> found({n}), triangle({h}), instance;
  py::array_t<int64_t> offsets({n + 1});
  py::array_t<float> t({h}), uvs;
  if (uv) uvs = py::array_t<float>({h, py::ssize_t(2)});
  if constexpr (kHasInstance<Record>) instance = py::array_t<uint32_t>({h});
  uint32_t* found_out = found.mutable_data();
  int64_t* offsets_out = offsets.mutable_data();
  float* t_out = t.mutable_data();
  uint32_t* triangle_out = triangle.mutable_data();
  uint32_t* instance_out = kHasInstance<Record> ? instance.mutable_data() : nullptr;
  float* uv_out = uv ? uvs.mutable_data() : nullptr;
  {
    py::gil_scoped_release release;
    all.gather([&](size_t i, uint32_t f, size_t offset) { found_out[i] = f, offsets_out[i] = int64_t(offset); },
               [&](size_t j, const Record& hit) {
                 t_out[j] = hit.t;
                 triangle_out[j] = hit.triangle;
                 if constexpr (kHasInstance<Record>) instance_out[j] = hit.instance;
                 if (uv_out) uv_out[2 * j] = hit.u, uv_out[2 * j + 1] = hit.v;
               });
    offsets_out[rays] = int64_t(all.hits());
  }
  py::dict d;
  d["found"] = found;
  d["offsets"] = offsets;
  d["t"] = t;
  if constexpr (kHasInstance<Record>) d["instance"] = instance;
  d["triangle"] = triangle;
  if (uv) d["uv"] = uvs;
  return d;
}

// query="all" answers arrays of the hits' count: out= has nothing to fill.
inline void refuse_out_for_all(Query query, const py::object& out) {
  if (query == Query::All && !out.is_none())
    throw py::value_error("out: query \"all\" answers arrays of the hits' count, made by the cast");
}

// A cast on the library's threads answered as Blob.cast and Scene.cast
// answer: one hit a ray (into out= where given) or every hit's rows.
// `float_origin`: the walk rounds origins to float (a blob), for the
// refusal's message; `invalid`: what a ray that is not one gets.
template <class Target>
py::dict cast_answer(const Target& target, const RayArrays& rays, Query query, Cull cull, HitOutputs outputs,
                     uint32_t max_hits, uint32_t threads, const py::object& out, bool float_origin,
                     Invalid invalid) {
  using Record = typename Target::Record;
  const bool uv = has(outputs, HitOutputs::Uv);
  refuse_out_for_all(query, out);
  if (query == Query::All) {
    AllHits<Target> all;
    {
      py::gil_scoped_release release;
      all = cast_all(target, rays, cull, outputs, max_hits, threads);
    }
    raise_for_refused(rays, all.refused, float_origin, invalid);
    return all_hits_answer(all, rays.count, uv);
  }
  const OneHitAnswer<Record> a(out, rays.shape, uv);
  Refused refused;
  {
    py::gil_scoped_release release;
    refused = cast_hits(target, rays, query, cull, outputs, threads, [&a](size_t i, const Record& h) { a.write(i, h); });
  }
  raise_for_refused(rays, refused, float_origin, invalid);
  return a.dict();
}

}  // namespace meshcast::python
