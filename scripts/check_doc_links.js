#!/usr/bin/env node
// check_doc_links.js [REPO]: every relative link in README.md and docs/**/*.md resolves: the
// file or folder exists, and an anchor (#...) names a heading of the markdown file it points to
// (GitHub's slugs: the heading's text lowercased, punctuation removed, spaces to '-', a
// repeated heading suffixed -1, -2, ...). Links to http(s)/mailto are not followed; fenced
// code and inline code are not read. Prints one line per broken link, FILE:LINE: TARGET:
// WHY, and exits 1 if there is any (0 otherwise). Run by ctest as doc_links (label fast).
'use strict';
const fs = require('fs');
const path = require('path');

const repo = path.resolve(process.argv[2] || path.join(__dirname, '..'));

function markdownFiles() {
  const files = [];
  if (fs.existsSync(path.join(repo, 'README.md'))) files.push(path.join(repo, 'README.md'));
  const walk = (dir) => {
    for (const e of fs.readdirSync(dir, { withFileTypes: true })) {
      const p = path.join(dir, e.name);
      if (e.isDirectory()) walk(p);
      else if (e.name.endsWith('.md')) files.push(p);
    }
  };
  if (fs.existsSync(path.join(repo, 'docs'))) walk(path.join(repo, 'docs'));
  return files;
}

// The file's lines with fenced code blocks blanked (line numbers kept) and inline code spans
// replaced by spaces of the same length.
function proseLines(text) {
  const lines = text.split('\n');
  let fence = null;
  return lines.map((line) => {
    const m = line.match(/^\s{0,3}(`{3,}|~{3,})/);
    if (fence) {
      if (m && m[1][0] === fence[0] && m[1].length >= fence.length) fence = null;
      return '';
    }
    if (m) { fence = m[1]; return ''; }
    return line.replace(/(`+)(?:(?!\1).)+?\1/g, (s) => ' '.repeat(s.length));
  });
}

function slug(heading) {
  // Code spans keep their text as written; elsewhere a link keeps its text, HTML tags go.
  let t = heading
    .split(/(`+[^`]*`+)/)
    .map((part, i) => (i % 2 ? part.replace(/`/g, '')
      : part.replace(/!?\[([^\]]*)\]\([^)]*\)/g, '$1').replace(/<[^>]+>/g, '')))
    .join('')
    .trim()
    .toLowerCase();
  t = t.replace(/[^\p{L}\p{M}\p{N}\p{Pc} -]/gu, '');
  return t.replace(/ /g, '-');
}

const anchorCache = new Map();
function anchorsOf(file) {
  if (anchorCache.has(file)) return anchorCache.get(file);
  const anchors = new Set();
  const seen = new Map();
  const raw = fs.readFileSync(file, 'utf8').split('\n');
  let fence = null;
  for (const line of raw) {
    const f = line.match(/^\s{0,3}(`{3,}|~{3,})/);
    if (fence) {
      if (f && f[1][0] === fence[0] && f[1].length >= fence.length) fence = null;
      continue;
    }
    if (f) { fence = f[1]; continue; }
    const h = line.match(/^\s{0,3}#{1,6}\s+(.*?)\s*#*\s*$/);
    if (h) {
      const base = slug(h[1]);
      const n = seen.get(base) || 0;
      seen.set(base, n + 1);
      anchors.add(n === 0 ? base : `${base}-${n}`);
    }
    for (const a of line.matchAll(/<a\s+(?:name|id)="([^"]+)"/g)) anchors.add(a[1]);
  }
  anchorCache.set(file, anchors);
  return anchors;
}

const broken = [];
let checked = 0;
for (const file of markdownFiles()) {
  const rel = path.relative(repo, file);
  const lines = proseLines(fs.readFileSync(file, 'utf8'));
  const targets = [];
  lines.forEach((line, i) => {
    // Inline links and images: ](target) or ](target "title") or ](<target>).
    for (const m of line.matchAll(/\]\(\s*(<[^>]*>|[^)\s]*)(?:\s+"[^"]*")?\s*\)/g)) {
      targets.push([i + 1, m[1].replace(/^<|>$/g, '')]);
    }
    // Reference definitions: [label]: target
    const d = line.match(/^\s{0,3}\[[^\]]+\]:\s*(\S+)/);
    if (d) targets.push([i + 1, d[1].replace(/^<|>$/g, '')]);
  });
  for (const [lineNo, target] of targets) {
    if (target === '' || /^[a-z][a-z0-9+.-]*:/i.test(target)) continue;  // a scheme: not ours
    checked++;
    const hash = target.indexOf('#');
    const filePart = decodeURIComponent(hash < 0 ? target : target.slice(0, hash));
    const anchor = hash < 0 ? null : decodeURIComponent(target.slice(hash + 1));
    const dest = filePart === '' ? file : path.resolve(path.dirname(file), filePart);
    const why = (() => {
      if (!fs.existsSync(dest)) return 'no such file';
      if (anchor === null || anchor === '') return null;
      if (!dest.endsWith('.md')) return null;  // line anchors in source files: not checked
      if (fs.statSync(dest).isDirectory()) return 'an anchor into a folder';
      return anchorsOf(dest).has(anchor) ? null : `no heading #${anchor} in ${path.relative(repo, dest)}`;
    })();
    if (why) broken.push(`${rel}:${lineNo}: ${target}: ${why}`);
  }
}
for (const b of broken) console.log(b);
if (broken.length) {
  console.error(`check_doc_links: ${broken.length} broken of ${checked} relative links`);
  process.exit(1);
}
console.log(`check_doc_links: ${checked} relative links, all resolve`);
