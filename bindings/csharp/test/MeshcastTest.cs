// The C# binding's test: answers equal the C++ library's on the same rays
// (the meshcast program's own casts of a public mesh, read from its hits
// file), answers known from a mesh's construction, scenes, casters, and
// failures as exceptions. Run by scripts/test.sh under Debian's Mono:
//   mono MeshcastTest.exe MESHCAST_PROGRAM MESH_FILE SCRATCH_DIR
// and, for the one-ray call's cost (bench/RESULTS.md):
//   mono MeshcastTest.exe bench BLOB RAYS
using System;
using System.Diagnostics;
using System.IO;
using Meshcast;

static class MeshcastTest {
  static int failures = 0;

  static void Check(bool ok, string what) {
    if (ok) return;
    Console.Error.WriteLine("FAILED: " + what);
    ++failures;
  }

  static void Throws<T>(Action call, string words, string what) where T : Exception {
    try {
      call();
    } catch (T e) {
      Check(e.Message.Contains(words), $"{what}: the message \"{e.Message}\" lacks \"{words}\"");
      return;
    }
    Check(false, $"{what}: no {typeof(T).Name}");
  }

  static void Run(string program, string arguments) {
    var start = new ProcessStartInfo(program, arguments) { UseShellExecute = false, RedirectStandardOutput = true };
    using (var p = Process.Start(start)) {
      p.StandardOutput.ReadToEnd();
      p.WaitForExit();
      if (p.ExitCode != 0) throw new Exception($"{program} {arguments}: exit {p.ExitCode}");
    }
  }

  // The C++ library's answers: the meshcast program builds the mesh's blob
  // and casts rays of each kind; this process casts the same rays through
  // the binding and compares every t and triangle, bit for bit.
  static void SameAsTheLibrary(string program, string mesh, string scratch) {
    string blobPath = Path.Combine(scratch, "cs_mesh.blob");
    Run(program, $"build \"{mesh}\" --out \"{blobPath}\"");
    using (var blob = Blob.Load(blobPath, map: true)) {
      foreach (var kind in new[] { "long", "probe", "radial", "segment" }) {
        string rays = Path.Combine(scratch, $"cs_{kind}.rays"), hits = Path.Combine(scratch, $"cs_{kind}.hits");
        Run(program, $"rays \"{mesh}\" --kind {kind} --count 20000 --seed 3 --out \"{rays}\"");
        Run(program, $"trace \"{blobPath}\" --rays \"{rays}\" --out \"{hits}\"");
        Ray[] batch = ReadRays(rays);
        var mine = new Hit[batch.Length];
        blob.Cast(batch, mine, threads: 0);
        using (var r = new BinaryReader(File.OpenRead(hits))) {
          Check(new string(r.ReadChars(4)) == "HITS" && r.ReadUInt32() == batch.Length, kind + ": a HITS file");
          int differ = 0;
          for (int i = 0; i < batch.Length; ++i) {
            float t = r.ReadSingle();
            uint triangle = r.ReadUInt32();
            if (BitConverter.ToInt32(BitConverter.GetBytes(t), 0) != BitConverter.ToInt32(BitConverter.GetBytes(mine[i].T), 0) ||
                triangle != mine[i].Triangle)
              ++differ;
          }
          Check(differ == 0, $"{kind} rays: {differ} of {batch.Length} answers differ from the C++ library's");
          Console.WriteLine($"  {kind}: {batch.Length} rays, the same answers as the C++ library");
        }
      }
    }
  }

  // A scene of the mesh twice (as it is, and turned a quarter about z and
  // halved, inside the first), cast by the meshcast program from a scene
  // file and by the binding from the same instances: every t, instance
  // and triangle the same, both instances hit.
  static void SceneAsTheLibrary(string program, string mesh, string scratch) {
    string blobPath = Path.Combine(scratch, "cs_mesh.blob"), scenePath = Path.Combine(scratch, "cs_scene.json");
    string rays = Path.Combine(scratch, "cs_scene.rays"), hits = Path.Combine(scratch, "cs_scene.hiti");
    File.WriteAllText(scenePath, "{\"meshes\": {\"m\": \"cs_mesh.blob\"}, \"instances\": [{\"mesh\": \"m\"}, " +
                      "{\"mesh\": \"m\", \"rotation_scale\": [0, -0.5, 0, 0.5, 0, 0, 0, 0, 0.5], " +
                      "\"translation\": [0, 0, 0]}]}");
    Run(program, $"rays \"{mesh}\" --kind long --count 20000 --seed 5 --out \"{rays}\"");
    Run(program, $"trace \"{scenePath}\" --rays \"{rays}\" --out \"{hits}\"");
    Ray[] floats = ReadRays(rays);
    var batch = new RayD[floats.Length];
    for (int i = 0; i < floats.Length; ++i) {
      Ray r = floats[i];
      batch[i] = new RayD(r.OrgX, r.OrgY, r.OrgZ, r.DirX, r.DirY, r.DirZ, r.TMax);
    }
    using (var blob = Blob.Load(blobPath))
    using (var scene = new Scene()) {
      MeshId m = scene.AddMesh(blob);
      scene.AddInstance(m, Transform.Translate(0, 0, 0));
      scene.AddInstance(m, new Transform { RotationScale = new float[] { 0, -0.5f, 0, 0.5f, 0, 0, 0, 0, 0.5f },
                                           Translation = new double[] { 0, 0, 0 } });
      scene.Commit();
      var mine = new SceneHit[floats.Length];
      scene.Cast(batch, mine, threads: 0);
      using (var r = new BinaryReader(File.OpenRead(hits))) {
        Check(new string(r.ReadChars(4)) == "HITI" && r.ReadUInt32() == floats.Length, "a HITI file");
        int differ = 0, found = 0, second = 0;
        for (int i = 0; i < floats.Length; ++i) {
          float t = r.ReadSingle();
          uint instance = r.ReadUInt32(), triangle = r.ReadUInt32();
          found += mine[i].Found ? 1 : 0;
          second += mine[i].Instance == 1 ? 1 : 0;
          if (BitConverter.ToInt32(BitConverter.GetBytes(t), 0) != BitConverter.ToInt32(BitConverter.GetBytes(mine[i].T), 0) ||
              instance != mine[i].Instance || triangle != mine[i].Triangle)
            ++differ;
        }
        Check(differ == 0 && second > 0 && second < found,
              $"a scene: {differ} of {floats.Length} answers differ from the C++ library's ({second} of {found} hits on the second)");
        Console.WriteLine($"  a scene of two instances: {floats.Length} rays ({found} hits, {second} on the second instance), " +
                          "the same answers as the C++ library");
      }
    }
  }

  static Ray[] ReadRays(string path) {
    using (var r = new BinaryReader(File.OpenRead(path))) {
      if (new string(r.ReadChars(4)) != "RAYS") throw new Exception(path + ": not a RAYS file");
      var rays = new Ray[r.ReadUInt32()];
      for (int i = 0; i < rays.Length; ++i)
        rays[i] = new Ray(r.ReadSingle(), r.ReadSingle(), r.ReadSingle(), r.ReadSingle(), r.ReadSingle(), r.ReadSingle(),
                          r.ReadSingle());
      return rays;
    }
  }

  // Two unit squares, A at z = 0 (triangles 0, 1) and B at z = 1 (2, 3),
  // split along x = y (triangles 0 and 2 hold x >= y).
  static readonly float[] Squares = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1 };
  static readonly uint[] Corners = { 0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7 };

  static void KnownAnswers() {
    using (var blob = Blob.Build(Squares, Corners, name: "two squares")) {
      Check(blob.TriangleCount == 4 && blob.Layout.StartsWith("OctTreeCompressed/"), "the blob's info");
      var rays = new[] { new Ray(0.75f, 0.25f, 2, 0, 0, -1), new Ray(0.25f, 0.75f, 2, 0, 0, -1), new Ray(3, 3, 2, 0, 0, -1) };
      var hits = new Hit[3];
      blob.Cast(rays, hits, outputs: HitOutputs.Uv);
      Check(hits[0].Triangle == 2 && hits[0].T == 1 && hits[1].Triangle == 3 && !hits[2].Found, "closest hits");
      // Spans: the second ray alone, answered into the middle of a larger array.
      var wide = new Hit[5];
      blob.Cast(new ReadOnlySpan<Ray>(rays, 1, 1), new Span<Hit>(wide, 2, 3));
      Check(wide[2].Triangle == 3 && wide[2].T == 1 && wide[1].T == 0 && wide[3].T == 0, "a cast of spans");
      blob.Cast(rays, hits, cull: Cull.Front);
      Check(!hits[0].Found && !hits[1].Found, "front faces culled");
      var found = new uint[3];
      var rows = new Hit[3 * 2];
      blob.CastAll(rays, 2, found, rows);
      Check(found[0] == 2 && rows[0].Triangle == 2 && rows[1].Triangle == 0 && rows[1].T == 2 && found[2] == 0, "every hit");
      ClosestPoint[] near = blob.ClosestPoints(new[] { 0.5f, 0.5f, 0.3f });
      Check(Math.Abs(near[0].Distance - 0.3f) < 1e-6f && near[0].Triangle == 0, "the nearest point");

      using (var scene = new Scene()) {
        MeshId mesh = scene.AddMesh(blob);
        InstanceId far = scene.AddInstance(mesh, Transform.Translate(1e9, 0, 0));
        InstanceId near0 = scene.AddInstance(mesh, Transform.Translate(0, 0, 0), mask: 1);
        scene.Commit();
        var sceneRays = new[] { new RayD(1e9 + 0.75, 0.25, 2, 0, 0, -1), new RayD(0.25, 0.75, 2, 0, 0, -1) };
        var sceneHits = new SceneHit[2];
        scene.Cast(sceneRays, sceneHits);
        Check(sceneHits[0].Instance == far.Index && sceneHits[0].Triangle == 2 && sceneHits[0].T == 1, "a far instance's hit");
        Check(sceneHits[1].Instance == near0.Index && sceneHits[1].Triangle == 3, "the near instance's hit");
        using (var second = new Scene()) {
          MeshId theirMesh = second.AddMesh(blob);
          InstanceId theirs = second.AddInstance(theirMesh, Transform.Translate(0, 0, 0));
          Check(theirs.Index == far.Index && theirs.Scene != far.Scene, "two scenes' first instances");
          Throws<MeshcastException>(() => scene.SetEnabled(theirs, false), "another scene", "another scene's instance");
          Throws<MeshcastException>(() => scene.AddInstance(theirMesh, Transform.Translate(0, 0, 0)), "another scene",
                                    "another scene's mesh");
        }
        scene.SetEnabled(near0, false);
        scene.Commit();
        scene.Cast(sceneRays, sceneHits);
        Check(!sceneHits[1].Found, "a disabled instance");

        using (var caster = Caster.Create(blob, Backend.Cpu))
        using (var other = Caster.Create(blob, Backend.Cpu)) {
          Ticket ticket = caster.Submit(rays);
          caster.Poll(ticket);
          Throws<MeshcastException>(() => other.Wait(ticket, hits), "", "another caster's ticket");
          var batch = new Hit[3];
          BatchRecord record = caster.Wait(ticket, batch);
          Check(batch[0].Triangle == 2 && batch[1].Triangle == 3 && record.Rays == 3 && record.RanOn == Backend.Cpu,
                "a caster's batch");
          var (where, why) = caster.BackendFor(1000);
          Check(where == Backend.Cpu && why.Length > 0, "the caster's backend and why");
        }
        using (var scenes = Caster.Create(null, Backend.Cpu)) {
          Ticket ticket = scenes.SubmitScene(scene, sceneRays);
          var batch = new SceneHit[2];
          scenes.WaitScene(ticket, batch);
          Check(batch[0].Instance == far.Index && !batch[1].Found, "a scene batch");
        }
      }
    }
  }

  static void Failures(string scratch) {
    var nan = (float[])Squares.Clone();
    nan[4] = float.NaN;
    try {
      Blob.Build(nan, Corners);
      Check(false, "a NaN vertex was built");
    } catch (MeshcastException e) {
      Check(e.Status == Status.Input && e.Message.Contains("vertex 1"), "a NaN vertex: " + e.Message);
    }
    Throws<MeshcastException>(() => Blob.Build(Squares, Corners, layout: "NoSuchTree/Float3"), "NoSuchTree", "a layout name");
    Throws<MeshcastException>(() => Blob.Load(Path.Combine(scratch, "missing.blob")), "missing.blob", "a missing file");
    Throws<MeshcastException>(() => Blob.FromBytes(new byte[100]), "blob in memory", "bytes that are no blob");
    var blob = Blob.Build(Squares, Corners);
    Throws<ArgumentException>(() => blob.Cast(new Ray[4], new Hit[2]), "fewer than the 4", "too few hits");
    blob.Dispose();
    Throws<ObjectDisposedException>(() => blob.Cast(new Ray[1], new Hit[1]), "Blob", "a disposed blob");
  }

  // One ray a call through the binding, in a loop: the median of 11
  // rounds of 200,000 calls for each ray of RAYS (bench/c_api_bench.cpp
  // writes a miss and a hit), ns a call.
  static int Bench(string blobPath, string raysPath) {
    using (var blob = Blob.Load(blobPath)) {
      Ray[] rays = ReadRays(raysPath);
      var one = new Ray[1];
      var hit = new Hit[1];
      const int calls = 200000;
      foreach (int k in new[] { 0, 1 }) {
        one[0] = rays[k];
        foreach (bool spans in new[] { false, true }) {
          var times = new double[11];
          for (int r = 0; r < times.Length; ++r) {
            var clock = Stopwatch.StartNew();
            if (spans)
              for (int i = 0; i < calls; ++i) blob.Cast(new ReadOnlySpan<Ray>(one), new Span<Hit>(hit));
            else
              for (int i = 0; i < calls; ++i) blob.Cast(one, hit);
            times[r] = clock.Elapsed.TotalMilliseconds * 1e6 / calls;
          }
          Array.Sort(times);
          Console.WriteLine($"| C# ({(spans ? "spans" : "arrays")}) | ray {k} ({(hit[0].Found ? "a hit" : "a miss")}) | " +
                            $"{times[times.Length / 2]:F1} ns a call |");
        }
      }
    }
    return 0;
  }

  static int Main(string[] args) {
    if (args.Length == 3 && args[0] == "bench") return Bench(args[1], args[2]);
    if (args.Length != 3) {
      Console.Error.WriteLine("usage: mono MeshcastTest.exe MESHCAST_PROGRAM MESH_FILE SCRATCH_DIR");
      return 2;
    }
    Console.WriteLine($"meshcast C API {Blob.ApiVersion >> 16}.{Blob.ApiVersion & 0xFFFF} from C#");
    SameAsTheLibrary(args[0], args[1], args[2]);
    SceneAsTheLibrary(args[0], args[1], args[2]);
    KnownAnswers();
    Failures(args[2]);
    if (failures > 0) {
      Console.Error.WriteLine($"{failures} checks failed");
      return 1;
    }
    Console.WriteLine("every check of the C# binding passed");
    return 0;
  }
}
