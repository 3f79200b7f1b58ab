// SPDX-License-Identifier: MIT
// The view's page: reads the server's messages (docs/view.md, "Messages")
// and draws the deformed surface, the tools, their forces, the strip chart
// and the controller's state.  It sends nothing: the page only watches.
'use strict';

var MAGIC = 0x56445249, HELLO = 1, FRAME = 2, PLAYBACK = 1;
var HELLO_HEAD = 108, FRAME_HEAD = 200, SAMPLE = 16, DEV = 64;
var STATES = ['init', 'ready', 'enabled', 'fault', 'off'], STATE_NONE = 255;
var FAULTS = ['clamp', 'workspace', 'velocity', 'watchdog', 'overrun', 'encoder NaN',
	'encoder range', 'signal', 'HAL read', 'HAL write', 'HAL fault', 'engine'];
var CHART_S = 5;                        // seconds the strip chart shows
var DEV_COLOURS = ['#e07000', '#a000c0'];

var params = new URLSearchParams(location.search);
var el = function (id) { return document.getElementById(id); };

var renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
var scene = new THREE.Scene();
var camera = new THREE.PerspectiveCamera(35, 1, 1e-4, 100);
var view = { mesh: null, outline: null, tips: [], proxies: [], arrows: [] };
var model = null;                       // the hello: mesh at rest, scale
var frames = [];                        // playback: every frame, in order
var samples = [];                       // the chart: {t, f0, f1, c}
var orbit = { theta: -1.1, phi: 0.95, dist: 1, target: new THREE.Vector3() };
var stats = { frames: 0, times: [], fps: 0, latency_ms: NaN, state: 'connecting', t: 0,
	dropped: 0, connected: false, probe: null, loaded: false };
var paused = false, playing = false, playT = 0, lastWall = 0;
window.irdmStats = stats;

renderer.setClearColor(0xf4f4f4);
scene.add(new THREE.AmbientLight(0xffffff, 0.55));
var sun = new THREE.DirectionalLight(0xffffff, 0.6);
scene.add(sun);
el('scene').appendChild(renderer.domElement);

// ---- colour scale: fixed for the run (the hello's scale_m is its top) ----
var RAMP = [[40, 70, 210], [0, 190, 220], [40, 200, 60], [240, 220, 0], [230, 40, 20]];
function ramp(x, out, k) {
	x = Math.max(0, Math.min(1, x)) * (RAMP.length - 1);
	var i = Math.min(Math.floor(x), RAMP.length - 2), f = x - i;
	for (var c = 0; c < 3; c++)
		out[k + c] = (RAMP[i][c] + f * (RAMP[i + 1][c] - RAMP[i][c])) / 255;
}

// ---- messages ----
function readHello(dv) {
	var n = dv.getUint32(16, true), m = dv.getUint32(20, true), name = '';
	for (var i = 0; i < 64 && dv.getUint8(44 + i); i++)
		name += String.fromCharCode(dv.getUint8(44 + i));
	var h = { mode: dv.getUint32(12, true), n: n, m: m, ndev: dv.getUint32(24, true),
		period: dv.getFloat32(28, true), scale: dv.getFloat32(32, true),
		duration: dv.getFloat32(36, true), nframes: dv.getUint32(40, true), name: name,
		rest: new Float32Array(dv.buffer.slice(HELLO_HEAD, HELLO_HEAD + 12 * n)),
		tris: new Uint32Array(dv.buffer.slice(HELLO_HEAD + 12 * n, HELLO_HEAD + 12 * n + 12 * m)) };
	return h;
}

function readFrame(dv) {
	var ns = dv.getUint32(24, true), nn = dv.getUint32(28, true), o = FRAME_HEAD;
	var f = { state: dv.getUint32(12, true), faults: dv.getUint32(16, true),
		ndev: dv.getUint32(20, true), tick: dv.getFloat64(32, true), t: dv.getFloat64(40, true),
		newest: dv.getFloat64(48, true), sent: dv.getFloat64(56, true),
		dropped: dv.getFloat64(64, true), dev: [], samples: [], pos: null };
	for (var d = 0; d < 2; d++) {
		var b = 72 + d * DEV, v = [];
		for (var k = 0; k < 12; k++)
			v.push(dv.getFloat32(b + 4 * k, true));
		f.dev.push({ tip: v.slice(0, 3), force: v.slice(3, 6), bary: v.slice(6, 9),
			tri: dv.getUint32(b + 48, true), proxy: dv.getUint32(b + 52, true) });
	}
	for (var i = 0; i < ns; i++, o += SAMPLE)
		f.samples.push({ t: dv.getFloat32(o, true), f0: dv.getFloat32(o + 4, true),
			f1: dv.getFloat32(o + 8, true), c: dv.getFloat32(o + 12, true) });
	if (dv.getUint32(8, true) & 1)
		f.pos = new Float32Array(dv.buffer.slice(o, o + 12 * nn));
	return f;
}

// ---- the scene ----
function dispose(o) {
	if (!o)
		return;
	scene.remove(o);
	if (o.geometry)
		o.geometry.dispose();
}

function build(h) {
	dispose(view.mesh);
	dispose(view.outline);
	view.tips.concat(view.proxies, view.arrows).forEach(function (o) { scene.remove(o); });
	var g = new THREE.BufferGeometry();
	g.setAttribute('position', new THREE.BufferAttribute(h.rest.slice(), 3));
	g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * h.n), 3));
	g.setIndex(new THREE.BufferAttribute(h.tris, 1));
	g.computeBoundingSphere();
	view.mesh = new THREE.Mesh(g, new THREE.MeshLambertMaterial({ vertexColors: THREE.VertexColors,
		side: THREE.DoubleSide }));
	scene.add(view.mesh);
	var rg = new THREE.BufferGeometry();
	rg.setAttribute('position', new THREE.BufferAttribute(h.rest, 3));
	rg.setIndex(new THREE.BufferAttribute(h.tris, 1));
	view.outline = new THREE.LineSegments(new THREE.EdgesGeometry(rg, 20),
		new THREE.LineBasicMaterial({ color: 0x404040, transparent: true, opacity: 0.35 }));
	scene.add(view.outline);
	var s = g.boundingSphere, r = s.radius;
	orbit.target.copy(s.center);
	orbit.dist = 4.5 * r;
	h.radius = r;
	view.tips = []; view.proxies = []; view.arrows = [];
	for (var d = 0; d < 2; d++) {
		var tip = new THREE.Mesh(new THREE.SphereGeometry(0.025 * r, 16, 12),
			new THREE.MeshLambertMaterial({ color: 0x303030 }));
		var px = new THREE.Mesh(new THREE.SphereGeometry(0.018 * r, 16, 12),
			new THREE.MeshLambertMaterial({ color: 0xffffff }));
		var ar = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(),
			r, DEV_COLOURS[d], 0.08 * r, 0.05 * r);
		tip.visible = px.visible = ar.visible = false;
		scene.add(tip); scene.add(px); scene.add(ar);
		view.tips.push(tip); view.proxies.push(px); view.arrows.push(ar);
	}
	colour(h.rest);
	el('legend-text').textContent = 'displacement 0 to ' + (1e3 * h.scale).toPrecision(3) +
		' mm (fixed scale)';
	el('where').textContent = 'irdm view: ' + h.name + (h.mode === PLAYBACK ? ' (recorded run)' :
		' (live)');
	el('playback').style.display = h.mode === PLAYBACK ? 'block' : 'none';
	layout();
}

function colour(pos) {
	var g = view.mesh.geometry, c = g.attributes.color.array, rest = model.rest;
	for (var i = 0; i < model.n; i++) {
		var dx = pos[3 * i] - rest[3 * i], dy = pos[3 * i + 1] - rest[3 * i + 1];
		var dz = pos[3 * i + 2] - rest[3 * i + 2];
		ramp(Math.sqrt(dx * dx + dy * dy + dz * dz) / model.scale, c, 3 * i);
	}
	g.attributes.color.needsUpdate = true;
}

function showPositions(pos) {
	var g = view.mesh.geometry;
	g.attributes.position.array.set(pos);
	g.attributes.position.needsUpdate = true;
	g.computeVertexNormals();
	colour(pos);
}

function proxyPoint(d, pos) {
	if (d.tri === 0xffffffff || d.tri >= model.m)
		return null;
	var p = new THREE.Vector3();
	for (var k = 0; k < 3; k++) {
		var v = model.tris[3 * d.tri + k];
		p.x += d.bary[k] * pos[3 * v];
		p.y += d.bary[k] * pos[3 * v + 1];
		p.z += d.bary[k] * pos[3 * v + 2];
	}
	return p;
}

function showDevices(f) {
	var pos = view.mesh.geometry.attributes.position.array, r = model.radius;
	stats.probe = null;
	for (var d = 0; d < 2; d++) {
		var dev = f.dev[d], on = d < f.ndev;
		view.tips[d].visible = on;
		if (on)
			view.tips[d].position.set(dev.tip[0], dev.tip[1], dev.tip[2]);
		var p = on ? proxyPoint(dev, pos) : null;
		view.proxies[d].visible = !!p;
		view.arrows[d].visible = false;
		if (p)
			view.proxies[d].position.copy(p);
		else if (on)
			p = view.tips[d].position.clone();     // no site: the force at the tip
		else
			continue;
		if (d === 0)
			stats.probe = project(p);
		// the force on the tool: the reaction of the force on the object
		var fv = new THREE.Vector3(-dev.force[0], -dev.force[1], -dev.force[2]), n = fv.length();
		if (n > 1e-3) {
			view.arrows[d].position.copy(p);
			view.arrows[d].setDirection(fv.normalize());
			view.arrows[d].setLength(Math.min(0.4 * r * n, 1.5 * r), 0.08 * r, 0.05 * r);
			view.arrows[d].visible = true;
		}
	}
}

// Where p lands on the page, in CSS pixels (the tests look there).
function project(p) {
	var v = p.clone().project(camera), c = renderer.domElement.getBoundingClientRect();
	return { x: c.left + (v.x + 1) / 2 * c.width, y: c.top + (1 - v.y) / 2 * c.height };
}

function stateText(f) {
	if (f.state === STATE_NONE)
		return 'surface only';
	var s = STATES[f.state] || ('state ' + f.state);
	if (f.state === 3) {
		var why = [];
		FAULTS.forEach(function (n, i) { if (i > 0 && (f.faults >> i) & 1) why.push(n); });
		s += why.length ? ': ' + why.join(', ') : '';
	}
	return s;
}

function showFrame(f) {
	if (f.pos)
		showPositions(f.pos);
	showDevices(f);
	var st = el('state');
	st.textContent = stateText(f);
	st.className = STATES[f.state] || '';
	stats.state = f.state === STATE_NONE ? 'surface-only' : STATES[f.state] || '';
	stats.t = f.t;
}

// ---- the strip chart: force per device (left axis), compute time (right) ----
function drawChart(tEnd) {
	var cv = el('chart'), g = cv.getContext('2d'), w = cv.width, h = cv.height;
	var x0 = 34, x1 = w - 44, y0 = 14, y1 = h - 20, fmax = 1, cmax = 10;
	var t0 = tEnd - CHART_S, vis = samples.filter(function (s) { return s.t >= t0 && s.t <= tEnd; });
	vis.forEach(function (s) { fmax = Math.max(fmax, s.f0, s.f1); cmax = Math.max(cmax, s.c); });
	g.fillStyle = '#fff'; g.fillRect(0, 0, w, h);
	g.strokeStyle = '#bbb'; g.lineWidth = 1; g.strokeRect(x0, y0, x1 - x0, y1 - y0);
	g.fillStyle = '#222'; g.font = '11px sans-serif';
	g.fillText('force (N)', x0, 10);
	g.fillText('compute (\u00b5s)', x1 - 70, 10);
	g.fillText(fmax.toPrecision(2), 2, y0 + 8);
	g.fillText('0', 20, y1);
	g.fillText(cmax.toFixed(0), x1 + 3, y0 + 8);
	g.fillText((t0 > 0 ? t0 : 0).toFixed(1) + ' s', x0, h - 5);
	g.fillText(tEnd.toFixed(1) + ' s', x1 - 30, h - 5);
	var X = function (t) { return x0 + (t - t0) / CHART_S * (x1 - x0); };
	var line = function (key, max, colour) {
		g.strokeStyle = colour; g.lineWidth = 2; g.beginPath();
		vis.forEach(function (s, i) {
			var y = y1 - s[key] / max * (y1 - y0);
			if (i) g.lineTo(X(s.t), y); else g.moveTo(X(s.t), y);
		});
		g.stroke();
	};
	line('c', cmax, '#999');
	for (var d = 0; d < (model ? Math.min(model.ndev, 2) : 1); d++)
		line(d ? 'f1' : 'f0', fmax, DEV_COLOURS[d]);
}

// ---- live: counters, latency ----
function countFrame(f) {
	var now = performance.now();
	stats.frames++;
	stats.times.push(now);
	while (stats.times.length && stats.times[0] < now - 1000)
		stats.times.shift();
	stats.fps = stats.times.length;
	stats.dropped = f.dropped;
	if (f.sent > 0)
		stats.latency_ms = (f.newest - f.tick) * model.period * 1e3 + (Date.now() - f.sent);
}

function showStats() {
	var s = stats.fps + ' frames/s, ' + (isNaN(stats.latency_ms) ? '-' :
		stats.latency_ms.toFixed(0) + ' ms') + ' behind the loop';
	if (model && model.mode === PLAYBACK)
		s = frames.length + (stats.loaded ? '' : ' of ' + model.nframes) + ' frames recorded';
	else if (stats.dropped)
		s += ', ' + stats.dropped + ' records dropped';
	el('stats').textContent = s;
	document.title = 'irdm view: ' + stats.state + ', ' + stats.fps + ' frames/s';
}

function onLive(f) {
	countFrame(f);
	Array.prototype.push.apply(samples, f.samples);
	while (samples.length && samples[0].t < f.t - 2 * CHART_S)
		samples.shift();
	if (paused)
		return;
	showFrame(f);
}

// ---- playback: every frame is kept; the slider picks the time ----
function onRecorded(f) {
	frames.push(f);
	Array.prototype.push.apply(samples, f.samples);
	stats.frames = frames.length;
	// the whole recording is there: show the time the address asks for
	if (frames.length === model.nframes) {
		stats.loaded = true;
		seek(parseFloat(params.get('t')) || 0);
	}
}

function frameAt(t) {
	var lo = 0, hi = frames.length - 1;
	while (lo < hi) {
		var mid = (lo + hi + 1) >> 1;
		if (frames[mid].t <= t) lo = mid; else hi = mid - 1;
	}
	return frames[lo];
}

function seek(t) {
	if (!frames.length)
		return;
	playT = Math.max(0, Math.min(t, model.duration));
	el('slider').value = Math.round(playT / model.duration * 1000);
	el('ptime').textContent = playT.toFixed(3) + ' s';
	// positions: the newest frame at or before t that has them
	var f = frameAt(playT), i = frames.indexOf(f);
	while (i > 0 && !frames[i].pos)
		i--;
	if (frames[i].pos)
		showPositions(frames[i].pos);
	showFrame({ state: f.state, faults: f.faults, ndev: f.ndev, dev: f.dev, t: f.t });
	stats.t = playT;
}

el('slider').addEventListener('input', function () {
	playing = false;
	el('play').textContent = 'play';
	seek(el('slider').value / 1000 * model.duration);
});
el('play').addEventListener('click', function () {
	playing = !playing;
	if (playing && playT >= model.duration)
		seek(0);
	el('play').textContent = playing ? 'stop' : 'play';
});
el('pause').addEventListener('click', function () { irdmPause(!paused); });
window.irdmPause = function (p) {
	paused = p;
	el('pause').textContent = paused ? 'resume' : 'pause';
};
window.irdmSeek = seek;
// For tests and scripts: where a point of the object frame lands (CSS
// pixels), an element's box, and the counters in one line.
window.irdmProject = function (x, y, z) {
	var p = project(new THREE.Vector3(x, y, z));
	return p.x.toFixed(1) + ' ' + p.y.toFixed(1);
};
window.irdmRect = function (id) {
	var r = el(id).getBoundingClientRect();
	return [r.left, r.top, r.width, r.height].map(function (v) { return v.toFixed(0); }).join(' ');
};
window.irdmReport = function () {
	return 'connected=' + (stats.connected ? 1 : 0) + ' frames=' + stats.frames + ' fps=' +
		stats.fps + ' t=' + stats.t.toFixed(3) + ' latency=' +
		(isNaN(stats.latency_ms) ? -1 : stats.latency_ms.toFixed(1)) + ' state=' + stats.state +
		' loaded=' + (stats.loaded ? 1 : 0);
};

// ---- the socket: reconnects by itself (the controller may restart) ----
function connect() {
	var ws = new WebSocket('ws://' + location.host + '/', 'irdm-view');
	ws.binaryType = 'arraybuffer';
	ws.onopen = function () { stats.connected = true; };
	ws.onmessage = function (e) {
		var dv = new DataView(e.data);
		if (dv.byteLength < 8 || dv.getUint32(0, true) !== MAGIC)
			return;
		var kind = dv.getUint32(4, true);
		if (kind === HELLO) {
			model = readHello(dv);
			frames = []; samples = []; stats.frames = 0; stats.loaded = false; stats.t = 0;
			build(model);
		} else if (kind === FRAME && model) {
			var f = readFrame(dv);
			if (model.mode === PLAYBACK) onRecorded(f); else onLive(f);
		}
	};
	ws.onclose = function () {
		stats.connected = false;
		stats.t = 0;
		stats.state = 'disconnected';
		el('state').textContent = 'disconnected: retrying';
		el('state').className = '';
		setTimeout(connect, 1000);
	};
}

// ---- camera: orbit (drag) and zoom (wheel) around the object ----
var drag = null;
renderer.domElement.addEventListener('mousedown', function (e) { drag = [e.clientX, e.clientY]; });
window.addEventListener('mouseup', function () { drag = null; });
window.addEventListener('mousemove', function (e) {
	if (!drag)
		return;
	orbit.theta -= (e.clientX - drag[0]) * 0.01;
	orbit.phi = Math.max(0.05, Math.min(3.09, orbit.phi - (e.clientY - drag[1]) * 0.01));
	drag = [e.clientX, e.clientY];
});
renderer.domElement.addEventListener('wheel', function (e) {
	orbit.dist *= Math.exp(e.deltaY * 0.001);
	e.preventDefault();
}, { passive: false });

function placeCamera() {
	var s = Math.sin(orbit.phi);
	camera.up.set(0, 0, 1);
	camera.position.set(orbit.target.x + orbit.dist * s * Math.cos(orbit.theta),
		orbit.target.y + orbit.dist * s * Math.sin(orbit.theta),
		orbit.target.z + orbit.dist * Math.cos(orbit.phi));
	camera.lookAt(orbit.target);
	sun.position.copy(camera.position).add(new THREE.Vector3(0, 0, orbit.dist));
}

function layout() {
	var c = el('scene'), w = c.clientWidth, h = c.clientHeight;
	renderer.setSize(w, h);
	camera.aspect = w / Math.max(h, 1);
	camera.updateProjectionMatrix();
}
window.addEventListener('resize', layout);

function animate(now) {
	requestAnimationFrame(animate);
	if (model && model.mode === PLAYBACK && playing) {
		seek(playT + (now - lastWall) * 1e-3 * parseFloat(el('speed').value));
		if (playT >= model.duration) {
			playing = false;
			el('play').textContent = 'play';
		}
	}
	lastWall = now;
	placeCamera();
	if (model && !paused) {
		drawChart(model.mode === PLAYBACK ? playT : stats.t);
		if (view.proxies[0].visible)
			stats.probe = project(view.proxies[0].position);
	}
	showStats();
	renderer.render(scene, camera);
}

layout();
connect();
requestAnimationFrame(animate);
