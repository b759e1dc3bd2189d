// meshcast for C#: the C API (include/meshcast/meshcast_c.h) through
// P/Invoke, in one file. Handles are IDisposable; a failed call throws a
// MeshcastException carrying the library's status and message. Batches
// are arrays of the library's own records (Ray, Hit, ...): blittable, so
// the runtime pins them and the library reads and writes them in place,
// never a copy. Needs libmeshcast_c.so where the runtime looks for native
// libraries (LD_LIBRARY_PATH, or beside the program).
using System;
using System.Runtime.InteropServices;
using System.Text;

namespace Meshcast {

public enum Status { Ok = 0, Input = 1, Usage = 2, Output = 3, Gpu = 4, OutOfMemory = 5, Internal = 6 }

/// <summary>A failed call: the library's status and its message (which
/// names the input and the limit it broke).</summary>
public class MeshcastException : Exception {
  public Status Status { get; }
  public MeshcastException(Status status, string message) : base(message) { Status = status; }
}

public enum QueryKind : uint { Closest = 0, Any = 1 }
public enum Cull : uint { None = 0, Back = 1, Front = 2 }
[Flags] public enum HitOutputs : uint { None = 0, Uv = 1, Point = 2 }
public enum Backend : uint { Cpu = 0, Vulkan = 1, Automatic = 2 }

/// <summary>A ray: o + t d for t in [TMin, TMax]. 32 bytes, meshcast_ray.</summary>
[StructLayout(LayoutKind.Sequential)]
public struct Ray {
  public float OrgX, OrgY, OrgZ, DirX, DirY, DirZ, TMax, TMin;
  public Ray(float ox, float oy, float oz, float dx, float dy, float dz, float tMax = float.PositiveInfinity,
             float tMin = 0) {
    OrgX = ox; OrgY = oy; OrgZ = oz; DirX = dx; DirY = dy; DirZ = dz; TMax = tMax; TMin = tMin;
  }
}

/// <summary>A hit (meshcast_hit): T (infinity on a miss) and the caller's
/// triangle (NoHit on a miss); U, V and the point when asked for.</summary>
[StructLayout(LayoutKind.Sequential)]
public struct Hit {
  public const uint NoHit = 0xFFFFFFFFu;
  public float T;
  public uint Triangle;
  public float U, V;
  public float PointX, PointY, PointZ;
  public bool Found => Triangle != NoHit;
}

/// <summary>A scene's ray, its origin in double (meshcast_ray_d, 48 bytes).</summary>
[StructLayout(LayoutKind.Sequential)]
public struct RayD {
  public double OrgX, OrgY, OrgZ;
  public float DirX, DirY, DirZ, TMax, TMin;
  uint reserved;
  public RayD(double ox, double oy, double oz, float dx, float dy, float dz, float tMax = float.PositiveInfinity,
              float tMin = 0) {
    OrgX = ox; OrgY = oy; OrgZ = oz; DirX = dx; DirY = dy; DirZ = dz; TMax = tMax; TMin = tMin; reserved = 0;
  }
}

/// <summary>A scene's hit: its instance and the mesh's triangle (meshcast_scene_hit).</summary>
[StructLayout(LayoutKind.Sequential)]
public struct SceneHit {
  public float T;
  public uint Instance, Triangle;
  public float U, V;
  public bool Found => Triangle != Hit.NoHit;
}

/// <summary>The nearest point of a mesh (meshcast_closest_point).</summary>
[StructLayout(LayoutKind.Sequential)]
public struct ClosestPoint {
  public float X, Y, Z, Distance;
  public uint Triangle;
  public float U, V;
}

/// <summary>An instance's placement: world = RotationScale (row-major 3x3)
/// mesh + Translation.</summary>
[StructLayout(LayoutKind.Sequential)]
public struct Transform {
  [MarshalAs(UnmanagedType.ByValArray, SizeConst = 9)] public float[] RotationScale;
  [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] Translation;
  public static Transform Translate(double x, double y, double z) {
    return new Transform { RotationScale = new float[] { 1, 0, 0, 0, 1, 0, 0, 0, 1 }, Translation = new[] { x, y, z } };
  }
}

/// <summary>A batch's receipt (meshcast_ticket), good with its caster alone.</summary>
[StructLayout(LayoutKind.Sequential)]
public struct Ticket {
  public ulong Id, Caster;
  public uint Slot, Reserved;
}

/// <summary>A mesh a scene gave (meshcast_mesh_id): good with that scene
/// alone, another refuses it. Index counts the scene's meshes from 0.</summary>
[StructLayout(LayoutKind.Sequential)]
public struct MeshId {
  public ulong Scene;
  public uint Index, Reserved;
}

/// <summary>An instance a scene gave (meshcast_instance_id): good with that
/// scene alone. Index is what hits report (SceneHit.Instance).</summary>
[StructLayout(LayoutKind.Sequential)]
public struct InstanceId {
  public ulong Scene;
  public uint Index, Reserved;
}

/// <summary>What a batch cost and where it ran (meshcast_batch_record).</summary>
[StructLayout(LayoutKind.Sequential)]
public struct BatchRecord {
  public Backend RanOn;
  public uint Rays;
  public double LatencyMs, DeviceMs, CpuMs;
}

static class Native {
  const string Lib = "meshcast_c";

  [StructLayout(LayoutKind.Sequential)]
  internal struct Mesh {
    public uint StructSize, IndexBits;
    public IntPtr Vertices;
    public ulong VertexCount, VertexStride;
    public IntPtr Indices;
    public ulong TriangleCount, TriangleStride;
  }

  [StructLayout(LayoutKind.Sequential)]
  internal struct BuildOptions {
    public uint StructSize, Threads;
    public IntPtr Layout, Name;
    public double MaxBytesPerTriangle, MaxError;
    public uint GoalMemory, TriangleIds;
  }

  [StructLayout(LayoutKind.Sequential)]
  internal struct Query {
    public uint StructSize, Kind, Cull, Outputs, Mask, Threads;
  }

  [StructLayout(LayoutKind.Sequential)]
  internal struct BlobInfo {
    public uint StructSize, TriangleCount;
    public ulong Bytes;
    public IntPtr Layout;
    public double ErrorBound;
  }

  [StructLayout(LayoutKind.Sequential)]
  internal struct CasterOptions {
    public uint StructSize, Backend, Frames, Threads, Outputs;
  }

  [DllImport(Lib)] internal static extern uint meshcast_api_version();
  [DllImport(Lib)] internal static extern IntPtr meshcast_last_error();
  [DllImport(Lib)] internal static extern void meshcast_build_options_init(out BuildOptions options);
  [DllImport(Lib)] internal static extern void meshcast_query_init(out Query query);
  [DllImport(Lib)] internal static extern void meshcast_caster_options_init(out CasterOptions options);
  [DllImport(Lib)] internal static extern Status meshcast_blob_build(ref Mesh mesh, ref BuildOptions options, out IntPtr blob);
  [DllImport(Lib)] internal static extern Status meshcast_blob_load(byte[] path, uint flags, out IntPtr blob);
  [DllImport(Lib)] internal static extern Status meshcast_blob_from_memory(byte[] bytes, ulong size, uint flags, byte[] name, out IntPtr blob);
  [DllImport(Lib)] internal static extern Status meshcast_blob_save(IntPtr blob, byte[] path);
  [DllImport(Lib)] internal static extern Status meshcast_blob_info_get(IntPtr blob, ref BlobInfo info);
  [DllImport(Lib)] internal static extern Status meshcast_blob_release(IntPtr blob);
  // Spans' first records by reference (pinned for the call), the counts
  // beside them.
  [DllImport(Lib, EntryPoint = "meshcast_blob_cast")]
  internal static extern Status meshcast_blob_cast_span(IntPtr blob, ref Ray rays, ulong count, ref Query query,
                                                        ref Hit hits, ulong capacity, out ulong notWalkable);
  [DllImport(Lib)] internal static extern Status meshcast_blob_cast_all(IntPtr blob, [In] Ray[] rays, ulong count, ref Query query,
                                                                       uint maxHits, [Out] uint[] found, [Out] Hit[] hits,
                                                                       ulong capacity, out ulong notWalkable);
  [DllImport(Lib)] internal static extern Status meshcast_blob_closest_points(IntPtr blob, [In] float[] points, ulong count,
                                                                             float maxDistance, uint threads,
                                                                             [Out] ClosestPoint[] output, ulong capacity);
  [DllImport(Lib)] internal static extern Status meshcast_scene_create(out IntPtr scene);
  [DllImport(Lib)] internal static extern Status meshcast_scene_add_mesh(IntPtr scene, IntPtr blob, out MeshId mesh);
  [DllImport(Lib)] internal static extern Status meshcast_scene_add_instance(IntPtr scene, MeshId mesh, ref Transform transform,
                                                                            uint mask, uint flipFacing, out InstanceId instance);
  [DllImport(Lib)] internal static extern Status meshcast_scene_set_transform(IntPtr scene, InstanceId instance, ref Transform transform);
  [DllImport(Lib)] internal static extern Status meshcast_scene_set_mask(IntPtr scene, InstanceId instance, uint mask);
  [DllImport(Lib)] internal static extern Status meshcast_scene_set_flip_facing(IntPtr scene, InstanceId instance, uint flip);
  [DllImport(Lib)] internal static extern Status meshcast_scene_set_enabled(IntPtr scene, InstanceId instance, uint enabled);
  [DllImport(Lib)] internal static extern Status meshcast_scene_remove_instance(IntPtr scene, InstanceId instance);
  [DllImport(Lib)] internal static extern Status meshcast_scene_commit(IntPtr scene);
  [DllImport(Lib)] internal static extern Status meshcast_scene_cast(IntPtr scene, [In] RayD[] rays, ulong count, ref Query query,
                                                                    [Out] SceneHit[] hits, ulong capacity, out ulong notWalkable);
  [DllImport(Lib)] internal static extern Status meshcast_scene_release(IntPtr scene);
  [DllImport(Lib)] internal static extern Status meshcast_caster_create(IntPtr blob, ref CasterOptions options, out IntPtr caster);
  [DllImport(Lib)] internal static extern Status meshcast_caster_submit(IntPtr caster, [In] Ray[] rays, ulong count, ref Query query,
                                                                       out Ticket ticket);
  [DllImport(Lib)] internal static extern Status meshcast_caster_submit_scene(IntPtr caster, IntPtr scene, [In] RayD[] rays,
                                                                             ulong count, ref Query query, out Ticket ticket);
  [DllImport(Lib)] internal static extern Status meshcast_caster_poll(IntPtr caster, ref Ticket ticket, out uint ready);
  [DllImport(Lib)] internal static extern Status meshcast_caster_wait(IntPtr caster, ref Ticket ticket, [Out] Hit[] hits,
                                                                     ulong capacity, out BatchRecord record);
  [DllImport(Lib)] internal static extern Status meshcast_caster_wait_scene(IntPtr caster, ref Ticket ticket, [Out] SceneHit[] hits,
                                                                           ulong capacity, out BatchRecord record);
  [DllImport(Lib)] internal static extern Status meshcast_caster_backend(IntPtr caster, uint rays, out Backend backend, out IntPtr why);
  [DllImport(Lib)] internal static extern Status meshcast_caster_release(IntPtr caster);

  // A status other than Ok as the exception that says why.
  internal static void Check(Status status) {
    if (status != Status.Ok) throw new MeshcastException(status, Text(meshcast_last_error()));
  }

  // A UTF-8 string the library owns, as a C# string.
  internal static string Text(IntPtr utf8) {
    if (utf8 == IntPtr.Zero) return "";
    int n = 0;
    while (Marshal.ReadByte(utf8, n) != 0) ++n;
    var bytes = new byte[n];
    Marshal.Copy(utf8, bytes, 0, n);
    return Encoding.UTF8.GetString(bytes);
  }

  // A C# string as the NUL-terminated UTF-8 bytes the library reads.
  internal static byte[] Utf8(string text) => text == null ? null : Encoding.UTF8.GetBytes(text + "\0");

  // A query built here, not by meshcast_query_init: a one-ray call then
  // crosses into the library once.
  static readonly uint QuerySize = (uint)Marshal.SizeOf<Query>();
  internal static Query MakeQuery(QueryKind kind, Cull cull, HitOutputs outputs, uint mask, uint threads) {
    return new Query { StructSize = QuerySize, Kind = (uint)kind, Cull = (uint)cull, Outputs = (uint)outputs, Mask = mask,
                       Threads = threads };
  }

  internal static void Room(Array answers, long needed, string what) {
    if (answers == null || answers.LongLength < needed)
      throw new ArgumentException($"{what} holds {answers?.LongLength ?? 0} answers, fewer than the {needed} asked for");
  }
}

/// <summary>Base of the handles: released once, by Dispose or the finalizer.</summary>
public abstract class Handle : IDisposable {
  internal IntPtr Pointer;
  protected Handle(IntPtr pointer) { Pointer = pointer; }
  protected abstract Status Release(IntPtr pointer);
  internal IntPtr Live {
    get {
      if (Pointer == IntPtr.Zero) throw new ObjectDisposedException(GetType().Name);
      return Pointer;
    }
  }
  public void Dispose() {
    if (Pointer != IntPtr.Zero) Native.Check(Release(Pointer));
    Pointer = IntPtr.Zero;
    GC.SuppressFinalize(this);
  }
  ~Handle() {
    if (Pointer != IntPtr.Zero) Release(Pointer);
  }
}

/// <summary>A mesh's blob: one byte buffer the CPU walkers (and the GPU)
/// read.</summary>
public sealed class Blob : Handle {
  Blob(IntPtr pointer) : base(pointer) {}
  protected override Status Release(IntPtr pointer) => Native.meshcast_blob_release(pointer);

  public static uint ApiVersion => Native.meshcast_api_version();

  /// <summary>Built from x, y, z floats and three indices a triangle; layout
  /// "TREE/TRIANGLES", "auto", or null for the recommended one.</summary>
  public static Blob Build(float[] vertices, uint[] indices, string layout = null, string name = "mesh", uint threads = 0) {
    if (vertices == null || indices == null) throw new ArgumentNullException(vertices == null ? "vertices" : "indices");
    var pinnedV = GCHandle.Alloc(vertices, GCHandleType.Pinned);
    var pinnedI = GCHandle.Alloc(indices, GCHandleType.Pinned);
    try {
      var mesh = new Native.Mesh {
        StructSize = (uint)Marshal.SizeOf<Native.Mesh>(), IndexBits = 32, Vertices = pinnedV.AddrOfPinnedObject(),
        VertexCount = (ulong)(vertices.Length / 3), VertexStride = 12, Indices = pinnedI.AddrOfPinnedObject(),
        TriangleCount = (ulong)(indices.Length / 3), TriangleStride = 0
      };
      if (vertices.Length % 3 != 0 || indices.Length % 3 != 0)
        throw new ArgumentException("vertices and indices come in threes");
      Native.meshcast_build_options_init(out var options);
      var layoutText = GCHandle.Alloc(Native.Utf8(layout), GCHandleType.Pinned);
      var nameText = GCHandle.Alloc(Native.Utf8(name), GCHandleType.Pinned);
      try {
        options.Layout = layout == null ? IntPtr.Zero : layoutText.AddrOfPinnedObject();
        options.Name = nameText.AddrOfPinnedObject();
        options.Threads = threads;
        Native.Check(Native.meshcast_blob_build(ref mesh, ref options, out var blob));
        return new Blob(blob);
      } finally {
        layoutText.Free();
        nameText.Free();
      }
    } finally {
      pinnedV.Free();
      pinnedI.Free();
    }
  }

  /// <summary>A blob file, read whole or mapped read-only.</summary>
  public static Blob Load(string path, bool map = false) {
    Native.Check(Native.meshcast_blob_load(Native.Utf8(path), map ? 1u : 0u, out var blob));
    return new Blob(blob);
  }

  /// <summary>A blob's bytes, copied and validated.</summary>
  public static Blob FromBytes(byte[] bytes, string name = "blob in memory") {
    Native.Check(Native.meshcast_blob_from_memory(bytes, (ulong)(bytes?.LongLength ?? 0), 0, Native.Utf8(name), out var blob));
    return new Blob(blob);
  }

  public void Save(string path) => Native.Check(Native.meshcast_blob_save(Live, Native.Utf8(path)));

  public uint TriangleCount => Info().TriangleCount;
  public string Layout => Native.Text(Info().Layout);
  public ulong Bytes => Info().Bytes;

  Native.BlobInfo Info() {
    var info = new Native.BlobInfo { StructSize = (uint)Marshal.SizeOf<Native.BlobInfo>() };
    Native.Check(Native.meshcast_blob_info_get(Live, ref info));
    return info;
  }

  /// <summary>The hit of each ray into hits (as long as rays at least);
  /// threads: 1 this thread, 0 every core. Returns the rays not walkable
  /// (answered as misses).</summary>
  public ulong Cast(Ray[] rays, Hit[] hits, QueryKind kind = QueryKind.Closest, Cull cull = Cull.None,
                    HitOutputs outputs = HitOutputs.None, uint threads = 1) {
    // Through the span call: Mono marshals an array parameter of structs at
    // about 250 ns a call more than a reference to its first record.
    Native.Room(hits, rays.LongLength, "hits");
    return Cast(new ReadOnlySpan<Ray>(rays), new Span<Hit>(hits), kind, cull, outputs, threads);
  }

  /// <summary>The same for spans of records (a slice of a larger array, or
  /// memory of one's own), read and written in place.</summary>
  public ulong Cast(ReadOnlySpan<Ray> rays, Span<Hit> hits, QueryKind kind = QueryKind.Closest, Cull cull = Cull.None,
                    HitOutputs outputs = HitOutputs.None, uint threads = 1) {
    if (hits.Length < rays.Length)
      throw new ArgumentException($"hits holds {hits.Length} answers, fewer than the {rays.Length} asked for");
    if (rays.Length == 0) return 0;
    var q = Native.MakeQuery(kind, cull, outputs, 0xFF, threads);
    Native.Check(Native.meshcast_blob_cast_span(Live, ref MemoryMarshal.GetReference(rays), (ulong)rays.Length, ref q,
                                                ref MemoryMarshal.GetReference(hits), (ulong)hits.Length, out var skipped));
    return skipped;
  }

  /// <summary>Every hit of each ray: found[i] along ray i, its nearest
  /// min(found[i], maxHits) at hits[i * maxHits ...].</summary>
  public ulong CastAll(Ray[] rays, uint maxHits, uint[] found, Hit[] hits, Cull cull = Cull.None,
                       HitOutputs outputs = HitOutputs.None, uint threads = 1) {
    Native.Room(found, rays.LongLength, "found");
    Native.Room(hits, rays.LongLength * maxHits, "hits");
    var q = Native.MakeQuery(QueryKind.Closest, cull, outputs, 0xFF, threads);
    Native.Check(Native.meshcast_blob_cast_all(Live, rays, (ulong)rays.LongLength, ref q, maxHits, found, hits,
                                               (ulong)hits.LongLength, out var skipped));
    return skipped;
  }

  /// <summary>The nearest point of the mesh to each point (x, y, z floats)
  /// within maxDistance.</summary>
  public ClosestPoint[] ClosestPoints(float[] points, float maxDistance = float.PositiveInfinity, uint threads = 1) {
    var found = new ClosestPoint[points.Length / 3];
    Native.Check(Native.meshcast_blob_closest_points(Live, points, (ulong)found.LongLength, maxDistance, threads, found,
                                                     (ulong)found.LongLength));
    return found;
  }
}

/// <summary>Instances of blobs, placed with double translations.</summary>
public sealed class Scene : Handle {
  public Scene() : base(Create()) {}
  static IntPtr Create() {
    Native.Check(Native.meshcast_scene_create(out var scene));
    return scene;
  }
  protected override Status Release(IntPtr pointer) => Native.meshcast_scene_release(pointer);

  /// <summary>The scene keeps the blob's bytes: the blob may be disposed after.</summary>
  public MeshId AddMesh(Blob blob) {
    Native.Check(Native.meshcast_scene_add_mesh(Live, blob.Live, out var mesh));
    return mesh;
  }
  public InstanceId AddInstance(MeshId mesh, Transform transform, byte mask = 0xFF, bool flipFacing = false) {
    Native.Check(Native.meshcast_scene_add_instance(Live, mesh, ref transform, mask, flipFacing ? 1u : 0u, out var id));
    return id;
  }
  public void SetTransform(InstanceId instance, Transform transform) =>
      Native.Check(Native.meshcast_scene_set_transform(Live, instance, ref transform));
  public void SetMask(InstanceId instance, byte mask) => Native.Check(Native.meshcast_scene_set_mask(Live, instance, mask));
  public void SetFlipFacing(InstanceId instance, bool flip) =>
      Native.Check(Native.meshcast_scene_set_flip_facing(Live, instance, flip ? 1u : 0u));
  public void SetEnabled(InstanceId instance, bool enabled) =>
      Native.Check(Native.meshcast_scene_set_enabled(Live, instance, enabled ? 1u : 0u));
  public void RemoveInstance(InstanceId instance) => Native.Check(Native.meshcast_scene_remove_instance(Live, instance));
  /// <summary>The edits so far, seen by the casts from now on.</summary>
  public void Commit() => Native.Check(Native.meshcast_scene_commit(Live));

  public ulong Cast(RayD[] rays, SceneHit[] hits, QueryKind kind = QueryKind.Closest, Cull cull = Cull.None,
                    byte mask = 0xFF, uint threads = 1) {
    Native.Room(hits, rays.LongLength, "hits");
    var q = Native.MakeQuery(kind, cull, HitOutputs.None, mask, threads);
    Native.Check(Native.meshcast_scene_cast(Live, rays, (ulong)rays.LongLength, ref q, hits, (ulong)hits.LongLength,
                                            out var skipped));
    return skipped;
  }
}

/// <summary>Batches cast a frame ahead, on the CPU's workers or the GPU.</summary>
public sealed class Caster : Handle {
  Caster(IntPtr pointer) : base(pointer) {}
  protected override Status Release(IntPtr pointer) => Native.meshcast_caster_release(pointer);

  /// <summary>blob null: a caster of scene batches alone.</summary>
  public static Caster Create(Blob blob, Backend backend = Backend.Automatic, uint frames = 4, uint threads = 0) {
    Native.meshcast_caster_options_init(out var options);
    options.Backend = (uint)backend; options.Frames = frames; options.Threads = threads;
    Native.Check(Native.meshcast_caster_create(blob?.Live ?? IntPtr.Zero, ref options, out var caster));
    return new Caster(caster);
  }

  public Ticket Submit(Ray[] rays, QueryKind kind = QueryKind.Closest, Cull cull = Cull.None) {
    var q = Native.MakeQuery(kind, cull, HitOutputs.None, 0xFF, 1);
    Native.Check(Native.meshcast_caster_submit(Live, rays, (ulong)rays.LongLength, ref q, out var ticket));
    return ticket;
  }
  public Ticket SubmitScene(Scene scene, RayD[] rays, QueryKind kind = QueryKind.Closest, byte mask = 0xFF) {
    var q = Native.MakeQuery(kind, Cull.None, HitOutputs.None, mask, 1);
    Native.Check(Native.meshcast_caster_submit_scene(Live, scene.Live, rays, (ulong)rays.LongLength, ref q, out var ticket));
    return ticket;
  }
  public bool Poll(Ticket ticket) {
    Native.Check(Native.meshcast_caster_poll(Live, ref ticket, out var ready));
    return ready != 0;
  }
  public BatchRecord Wait(Ticket ticket, Hit[] hits) {
    Native.Check(Native.meshcast_caster_wait(Live, ref ticket, hits, (ulong)(hits?.LongLength ?? 0), out var record));
    return record;
  }
  public BatchRecord WaitScene(Ticket ticket, SceneHit[] hits) {
    Native.Check(Native.meshcast_caster_wait_scene(Live, ref ticket, hits, (ulong)(hits?.LongLength ?? 0), out var record));
    return record;
  }
  /// <summary>Where a batch of this many rays would go now, and why.</summary>
  public (Backend, string) BackendFor(uint rays) {
    Native.Check(Native.meshcast_caster_backend(Live, rays, out var backend, out var why));
    return (backend, Native.Text(why));
  }
}

}  // namespace Meshcast
