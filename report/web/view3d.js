// The report's 3D view: the fitted ball's .glb (embedded in the page as base64) played on
// its floor with three.js, with play/pause and a scrub slider. Bundled with three.js into
// one script at build time (report/CMakeLists.txt), so the page needs no network.
//
// The page says in #view3d's data attributes what it drew (state, drawnPixels: pixels
// unlike the background), for the headless check. A URL hash "#t=0.9" holds the view
// paused at that time (s since the release), for screenshots.
import {
  AmbientLight, AnimationMixer, Color, DirectionalLight, PerspectiveCamera, Scene, Vector3,
  WebGLRenderer,
} from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const BACKGROUND = 0xf4f6f8;

function bytesOf(base64) {
  const text = atob(base64.trim());
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i);
  return bytes.buffer;
}

// Pixels of the drawn frame that differ from the background (> 0 when anything is drawn)
// and of them those of the fitted ball's orange.
function drawnPixels(renderer) {
  const gl = renderer.getContext();
  const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
  const px = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const bg = new Color(BACKGROUND);
  const r = Math.round(bg.r * 255), g = Math.round(bg.g * 255), b = Math.round(bg.b * 255);
  let n = 0, ball = 0;
  for (let i = 0; i < px.length; i += 4) {
    if (Math.abs(px[i] - r) + Math.abs(px[i + 1] - g) + Math.abs(px[i + 2] - b) > 24) n++;
    if (px[i] > 150 && px[i] > px[i + 1] + 50 && px[i + 1] > px[i + 2] + 20) ball++;
  }
  return [n, ball];
}

function start(root) {
  const canvas = root.querySelector('canvas');
  const slider = root.querySelector('input[type=range]');
  const button = root.querySelector('button');
  const label = root.querySelector('.view3d-time');
  const say = (state) => { root.dataset.state = state; };
  let renderer;
  try {
    renderer = new WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    say('error: no WebGL (' + e.message + ')');
    label.textContent = 'This browser draws no WebGL: the 3D view is unavailable.';
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(canvas.clientWidth, canvas.clientHeight, false);
  const scene = new Scene();
  scene.background = new Color(BACKGROUND);
  scene.add(new AmbientLight(0xffffff, 1.2));
  const sun = new DirectionalLight(0xffffff, 2.2);
  sun.position.set(1, 3, 2);
  scene.add(sun);
  const camera = new PerspectiveCamera(35, canvas.clientWidth / canvas.clientHeight, 0.005, 100);
  const controls = new OrbitControls(camera, canvas);

  const glb = bytesOf(document.getElementById(root.dataset.glb).textContent);
  new GLTFLoader().parse(glb, '', (gltf) => {
    scene.add(gltf.scene);
    const extras = gltf.asset.extras || {};
    const drop = (extras.animation && extras.animation.drop_height_m) || 1;
    const animation = extras.animation || {};
    const recorded = gltf.scene.getObjectByName('recorded_ball') ? (animation.recorded_ball_offset_x_m || 0) : 0;
    // From the front and a little above, the whole drop in view.
    const target = new Vector3(recorded / 2, drop * 0.45, 0);
    camera.position.set(target.x + drop * 0.3, drop * 0.55, drop * 1.9 + 0.2);
    controls.target.copy(target);
    controls.update();

    const mixer = new AnimationMixer(gltf.scene);
    const clip = gltf.animations[0];
    mixer.clipAction(clip).play();
    slider.max = clip.duration.toFixed(3);
    const hash = /#t=([0-9.]+)/.exec(window.location.hash);
    let t = hash ? Math.min(parseFloat(hash[1]), clip.duration) : 0;
    let playing = !hash;
    if (hash) root.scrollIntoView();  // a screenshot's view at the top of the page
    let last = performance.now();
    const show = () => {
      mixer.setTime(t);
      renderer.render(scene, camera);
      slider.value = t.toFixed(3);
      label.textContent = 't = ' + t.toFixed(3) + ' s of ' + clip.duration.toFixed(2) + ' s';
    };
    button.textContent = playing ? 'Pause' : 'Play';
    button.onclick = () => {
      playing = !playing;
      button.textContent = playing ? 'Pause' : 'Play';
      last = performance.now();
    };
    slider.oninput = () => {
      playing = false;
      button.textContent = 'Play';
      t = parseFloat(slider.value);
      show();
    };
    controls.addEventListener('change', show);
    const frame = (now) => {
      if (playing) {
        t += (now - last) / 1000;
        if (t > clip.duration) t = 0;
        show();
      }
      last = now;
      requestAnimationFrame(frame);
    };
    show();
    [root.dataset.drawnPixels, root.dataset.ballPixels] = drawnPixels(renderer).map(String);
    say('drawn');
    requestAnimationFrame(frame);
  }, (error) => {
    say('error: ' + error.message);
    label.textContent = 'The fitted ball could not be read: ' + error.message;
  });
}

document.querySelectorAll('.view3d').forEach(start);
