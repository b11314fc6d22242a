// surfprep's HTML report: a small WebGL viewer written for the page (no library).
//
// The scene comes from the JSON script element #surfprep-scene (written by
// plugin/report_html.py): coordinates relative to the scene's centre as base64 of
// little-endian Float32Array bytes, triangle indices as Uint32Array, colours as Uint8Array.
// Triangles are lit by a headlight (Lambert), lines are drawn unlit; an orbit camera turns
// about +z (turntable), zooms with the wheel and pans with right-drag or shift-drag.
//
// What happened is told through document.body.dataset.rendered:
//   "webgl" (first frame drawn, no WebGL error), "no-webgl", "error", "no-scene".
(function () {
  "use strict";

  var body = document.body;
  var sceneElement = document.getElementById("surfprep-scene");
  var canvas = document.getElementById("view-canvas");
  if (!sceneElement || !canvas) {
    body.dataset.rendered = "no-scene";
    return;
  }

  // Replace the view by a message (no WebGL, or drawing failed); the rest of the page stays.
  function showMessage(text) {
    var message = document.getElementById("view-message");
    canvas.hidden = true;
    document.getElementById("view").classList.add("unavailable");
    ["legend", "scales", "controls"].forEach(function (id) {
      var element = document.getElementById(id);
      if (element) element.hidden = true;
    });
    message.textContent = text;
    message.hidden = false;
  }

  var gl = null;
  try {
    gl = canvas.getContext("webgl", { antialias: true, alpha: false });
  } catch (ignored) {
    gl = null;
  }
  if (!gl) {
    showMessage("The 3-D view needs WebGL, which this browser does not provide (or has switched " +
                "off). The summary, tables and images below are complete without it.");
    body.dataset.rendered = "no-webgl";
    return;
  }

  // ------------------------------------------------------------- decoding the scene
  function bytes(b64) {
    var text = atob(b64), out = new Uint8Array(text.length);
    for (var i = 0; i < text.length; i++) out[i] = text.charCodeAt(i);
    return out;
  }
  function float32(b64) { return new Float32Array(bytes(b64).buffer); }
  function uint32(b64) { return new Uint32Array(bytes(b64).buffer); }

  // A batch of triangles drawn as separate vertices (flat shading needs a normal per
  // triangle; WebGL 1 has neither flat varyings nor 32-bit indices without extensions).
  function Triangles(count) {
    this.position = new Float32Array(count * 9);
    this.normal = new Float32Array(count * 9);
    this.color = new Uint8Array(count * 9);
    this.n = 0;                                   // vertices written
  }
  Triangles.prototype.add = function (P, a, b, c, ca, cb, cc) {
    var ux = P[3 * b] - P[3 * a], uy = P[3 * b + 1] - P[3 * a + 1], uz = P[3 * b + 2] - P[3 * a + 2];
    var vx = P[3 * c] - P[3 * a], vy = P[3 * c + 1] - P[3 * a + 1], vz = P[3 * c + 2] - P[3 * a + 2];
    var nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    var len = Math.sqrt(nx * nx + ny * ny + nz * nz) || 1;
    var corners = [a, b, c], colors = [ca, cb, cc];
    for (var k = 0; k < 3; k++) {
      var o = 3 * this.n;
      this.position.set(P.subarray(3 * corners[k], 3 * corners[k] + 3), o);
      this.normal[o] = nx / len; this.normal[o + 1] = ny / len; this.normal[o + 2] = nz / len;
      this.color.set(colors[k], o);
      this.n++;
    }
  };

  // A batch of line segments: pairs of vertices, one colour each.
  function Segments(count) {
    this.position = new Float32Array(count * 6);
    this.color = new Uint8Array(count * 6);
    this.n = 0;
  }
  Segments.prototype.add = function (P, a, b, rgb) {
    this.position.set(P.subarray(3 * a, 3 * a + 3), 3 * this.n);
    this.color.set(rgb, 3 * this.n);
    this.position.set(P.subarray(3 * b, 3 * b + 3), 3 * this.n + 3);
    this.color.set(rgb, 3 * this.n + 3);
    this.n += 2;
  };

  // Per item of the scene: {group, triangles: Triangles|null, segments: Segments|null}.
  function buildItems(scene) {
    var items = [];
    scene.meshes.forEach(function (mesh) {
      var P = float32(mesh.pos), I = uint32(mesh.idx);
      var C = mesh.col ? bytes(mesh.col) : null;
      var tri = new Triangles(I.length / 3);
      for (var t = 0; t < I.length; t += 3) {
        var a = I[t], b = I[t + 1], c = I[t + 2];
        if (C) tri.add(P, a, b, c, C.subarray(3 * a, 3 * a + 3), C.subarray(3 * b, 3 * b + 3),
                       C.subarray(3 * c, 3 * c + 3));
        else tri.add(P, a, b, c, mesh.color, mesh.color, mesh.color);
      }
      items.push({ group: mesh.group, triangles: tri, segments: null });
    });
    scene.lines.forEach(function (line) {
      var P = float32(line.pos), n = P.length / 3, seg = new Segments(n - 1);
      for (var k = 0; k + 1 < n; k++) seg.add(P, k, k + 1, line.color);
      items.push({ group: line.group, triangles: null, segments: seg });
    });
    scene.grids.forEach(function (grid) {
      var P = float32(grid.pos), ni = grid.ni, nj = grid.nj;
      var C = grid.cellCol ? bytes(grid.cellCol) : null;
      var tri = new Triangles(2 * (ni - 1) * (nj - 1));
      var seg = new Segments(ni * (nj - 1) + (ni - 1) * nj);
      var node = function (i, j) { return i * nj + j; };
      for (var i = 0; i + 1 < ni; i++) {
        for (var j = 0; j + 1 < nj; j++) {
          var rgb = C ? C.subarray(3 * (i * (nj - 1) + j), 3 * (i * (nj - 1) + j) + 3) : grid.color;
          tri.add(P, node(i, j), node(i + 1, j), node(i + 1, j + 1), rgb, rgb, rgb);
          tri.add(P, node(i, j), node(i + 1, j + 1), node(i, j + 1), rgb, rgb, rgb);
        }
      }
      for (i = 0; i < ni; i++) for (j = 0; j + 1 < nj; j++) seg.add(P, node(i, j), node(i, j + 1), grid.lineColor);
      for (i = 0; i + 1 < ni; i++) for (j = 0; j < nj; j++) seg.add(P, node(i, j), node(i + 1, j), grid.lineColor);
      items.push({ group: grid.group, triangles: tri, segments: seg });
    });
    return items;
  }

  // ------------------------------------------------------------- WebGL
  var VERTEX_SHADER = [
    "attribute vec3 aPosition; attribute vec3 aNormal; attribute vec3 aColor;",
    "uniform mat4 uModelView; uniform mat4 uProjection; uniform mat3 uNormalMatrix;",
    "varying vec3 vNormal; varying vec3 vColor;",
    "void main() {",
    "  vNormal = uNormalMatrix * aNormal;",
    "  vColor = aColor;",
    "  gl_Position = uProjection * uModelView * vec4(aPosition, 1.0);",
    "}"].join("\n");
  var FRAGMENT_SHADER = [
    "precision mediump float;",
    "varying vec3 vNormal; varying vec3 vColor; uniform float uLit;",
    "void main() {",
    "  float shade = 1.0;",
    "  if (uLit > 0.5) {",
    "    // a light at the camera, a little above and right of the view axis, so that faces",
    "    // seen at the same angle (a cube from its diagonal) get different shades",
    "    float lambert = abs(dot(normalize(vNormal), vec3(0.3487, 0.4650, 0.8137)));",
    "    shade = 0.32 + 0.68 * lambert;",
    "    if (!gl_FrontFacing) shade *= 0.72;             // back faces a shade darker",
    "  }",
    "  gl_FragColor = vec4(vColor * shade, 1.0);",
    "}"].join("\n");

  function compile(type, source) {
    var shader = gl.createShader(type);
    gl.shaderSource(shader, source);
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(shader));
    return shader;
  }

  function program() {
    var p = gl.createProgram();
    gl.attachShader(p, compile(gl.VERTEX_SHADER, VERTEX_SHADER));
    gl.attachShader(p, compile(gl.FRAGMENT_SHADER, FRAGMENT_SHADER));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    return p;
  }

  function buffer(data) {
    var b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    return b;
  }

  // ------------------------------------------------------------- camera
  // rotation: 3x3 row-major, world -> camera axes (rows: right, up, back).
  function multiply3(a, b) {
    var out = new Array(9);
    for (var r = 0; r < 3; r++) for (var c = 0; c < 3; c++)
      out[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
    return out;
  }
  function axisRotation(x, y, z, angle) {            // about the unit axis (x, y, z)
    var c = Math.cos(angle), s = Math.sin(angle), t = 1 - c;
    return [t * x * x + c, t * x * y - s * z, t * x * z + s * y,
            t * x * y + s * z, t * y * y + c, t * y * z - s * x,
            t * x * z - s * y, t * y * z + s * x, t * z * z + c];
  }
  function isometric() {                              // looking from (1, -1, 1), z up
    var s2 = Math.SQRT1_2, s3 = 1 / Math.sqrt(3), s6 = 1 / Math.sqrt(6);
    return [s2, s2, 0, -s6, s6, 2 * s6, s3, -s3, s3];
  }

  function run(gl, scene) {
    var prog = program();
    var loc = {
      position: gl.getAttribLocation(prog, "aPosition"),
      normal: gl.getAttribLocation(prog, "aNormal"),
      color: gl.getAttribLocation(prog, "aColor"),
      modelView: gl.getUniformLocation(prog, "uModelView"),
      projection: gl.getUniformLocation(prog, "uProjection"),
      normalMatrix: gl.getUniformLocation(prog, "uNormalMatrix"),
      lit: gl.getUniformLocation(prog, "uLit")
    };
    var triangleCount = 0, segmentCount = 0;
    var draws = buildItems(scene).map(function (item) {
      var d = { group: item.group };
      if (item.triangles && item.triangles.n) {
        d.tri = { n: item.triangles.n, position: buffer(item.triangles.position),
                  normal: buffer(item.triangles.normal), color: buffer(item.triangles.color) };
        triangleCount += item.triangles.n / 3;
      }
      if (item.segments && item.segments.n) {
        d.seg = { n: item.segments.n, position: buffer(item.segments.position),
                  color: buffer(item.segments.color) };
        segmentCount += item.segments.n / 2;
      }
      return d;
    });

    var radius = scene.radius, fov = 30 * Math.PI / 180;
    var camera = {};
    function resetView() {
      var aspect = canvas.clientWidth / Math.max(canvas.clientHeight, 1);
      var half = Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * aspect)) / 2;
      camera.rotation = isometric();
      camera.target = [0, 0, 0];
      camera.distance = 1.05 * radius / Math.sin(half);
    }

    function hiddenGroups() {
      var hidden = {};
      document.querySelectorAll("input.group-toggle").forEach(function (box) {
        if (!box.checked) hidden[box.dataset.group] = true;
      });
      return hidden;
    }

    function bindAttribute(location, buf, size, type, normalized) {
      gl.bindBuffer(gl.ARRAY_BUFFER, buf);
      gl.enableVertexAttribArray(location);
      gl.vertexAttribPointer(location, size, type, normalized, 0, 0);
    }

    function draw() {
      var dpr = window.devicePixelRatio || 1;
      var w = Math.max(1, Math.round(canvas.clientWidth * dpr));
      var h = Math.max(1, Math.round(canvas.clientHeight * dpr));
      if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
      gl.viewport(0, 0, w, h);
      gl.clearColor(0.957, 0.965, 0.976, 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      gl.enable(gl.DEPTH_TEST);

      // modelView = translate(0, 0, -distance) * rotation * translate(-target), column-major
      var R = camera.rotation, t = camera.target, d = camera.distance;
      var tx = -(R[0] * t[0] + R[1] * t[1] + R[2] * t[2]);
      var ty = -(R[3] * t[0] + R[4] * t[1] + R[5] * t[2]);
      var tz = -(R[6] * t[0] + R[7] * t[1] + R[8] * t[2]) - d;
      var modelView = [R[0], R[3], R[6], 0, R[1], R[4], R[7], 0, R[2], R[5], R[8], 0, tx, ty, tz, 1];
      var far = d + 2 * radius, near = Math.max(d - 1.5 * radius, far * 1e-4);
      var f = 1 / Math.tan(fov / 2), aspect = w / h;
      var projection = [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / (near - far), -1,
                        0, 0, 2 * far * near / (near - far), 0];
      gl.useProgram(prog);
      gl.uniformMatrix4fv(loc.modelView, false, new Float32Array(modelView));
      gl.uniformMatrix4fv(loc.projection, false, new Float32Array(projection));
      gl.uniformMatrix3fv(loc.normalMatrix, false, new Float32Array([R[0], R[3], R[6], R[1], R[4], R[7], R[2], R[5], R[8]]));

      var hidden = hiddenGroups();
      // triangles pushed back a little so lines on them (grid lines, curves) stay visible
      gl.enable(gl.POLYGON_OFFSET_FILL);
      gl.polygonOffset(1, 1);
      gl.uniform1f(loc.lit, 1);
      draws.forEach(function (item) {
        if (!item.tri || hidden[item.group]) return;
        bindAttribute(loc.position, item.tri.position, 3, gl.FLOAT, false);
        bindAttribute(loc.normal, item.tri.normal, 3, gl.FLOAT, false);
        bindAttribute(loc.color, item.tri.color, 3, gl.UNSIGNED_BYTE, true);
        gl.drawArrays(gl.TRIANGLES, 0, item.tri.n);
      });
      gl.disable(gl.POLYGON_OFFSET_FILL);
      gl.uniform1f(loc.lit, 0);
      gl.disableVertexAttribArray(loc.normal);
      gl.vertexAttrib3f(loc.normal, 0, 0, 1);
      draws.forEach(function (item) {
        if (!item.seg || hidden[item.group]) return;
        bindAttribute(loc.position, item.seg.position, 3, gl.FLOAT, false);
        bindAttribute(loc.color, item.seg.color, 3, gl.UNSIGNED_BYTE, true);
        gl.drawArrays(gl.LINES, 0, item.seg.n);
      });
    }

    var pending = false;
    function requestDraw() {
      if (pending) return;
      pending = true;
      window.requestAnimationFrame(function () { pending = false; draw(); });
    }

    // ----------------------------------------------------------- interaction
    var drag = null;
    canvas.addEventListener("contextmenu", function (event) { event.preventDefault(); });
    canvas.addEventListener("pointerdown", function (event) {
      var pan = event.button === 2 || event.button === 1 || event.shiftKey;
      drag = { x: event.clientX, y: event.clientY, pan: pan };
      canvas.setPointerCapture(event.pointerId);
      canvas.classList.add("dragging");
    });
    canvas.addEventListener("pointermove", function (event) {
      if (!drag) return;
      var dx = event.clientX - drag.x, dy = event.clientY - drag.y;
      drag.x = event.clientX; drag.y = event.clientY;
      var R = camera.rotation;
      if (drag.pan) {                                 // move the target in the view plane
        var scale = 2 * camera.distance * Math.tan(fov / 2) / Math.max(canvas.clientHeight, 1);
        for (var k = 0; k < 3; k++) camera.target[k] -= scale * (dx * R[k] - dy * R[3 + k]);
      } else {                                        // turntable: about world z, then camera x
        R = multiply3(R, axisRotation(0, 0, 1, dx * 0.008));
        R = multiply3(axisRotation(1, 0, 0, dy * 0.008), R);
        camera.rotation = R;
      }
      requestDraw();
    });
    function endDrag() { drag = null; canvas.classList.remove("dragging"); }
    canvas.addEventListener("pointerup", endDrag);
    canvas.addEventListener("pointercancel", endDrag);
    canvas.addEventListener("wheel", function (event) {
      event.preventDefault();
      var step = event.deltaMode === 1 ? 0.05 : 0.0015;   // lines or pixels
      camera.distance *= Math.exp(event.deltaY * step);
      camera.distance = Math.min(Math.max(camera.distance, radius * 1e-4), radius * 1e3);
      requestDraw();
    }, { passive: false });
    document.getElementById("reset-view").addEventListener("click", function () {
      resetView();
      requestDraw();
    });
    document.querySelectorAll("input.group-toggle").forEach(function (box) {
      box.addEventListener("change", requestDraw);
    });
    window.addEventListener("resize", requestDraw);
    canvas.addEventListener("webglcontextlost", function (event) {
      event.preventDefault();
      showMessage("The 3-D view lost its WebGL context; reload the page to see it again.");
    });

    // ----------------------------------------------------------- first frame
    resetView();
    draw();
    var status = gl.getError();
    if (status !== gl.NO_ERROR) throw new Error("WebGL error 0x" + status.toString(16));
    body.dataset.triangles = String(triangleCount);
    body.dataset.segments = String(segmentCount);
    body.dataset.rendered = "webgl";
  }

  // ------------------------------------------------------------- start
  try {
    run(gl, JSON.parse(sceneElement.textContent));
  } catch (error) {
    showMessage("The 3-D view could not be drawn: " + error.message +
                ". The summary, tables and images below are complete without it.");
    body.dataset.rendered = "error";
    console.error(error);
  }
})();
