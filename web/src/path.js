// path.js: the path and point syntax of the page's URL and of scripts/web-check.sh.

// "x,y,z" -> [x, y, z] (finite numbers), else throws naming the text.
export function vec3(text) {
  const v = text.split(",").map(Number);
  if (v.length !== 3 || v.some((x) => !Number.isFinite(x))) throw new Error(`bad point "${text}"`);
  return v;
}

// "x,y,z[@lx,ly,lz];..." -> [{eye, look (null without @)}]
export function parsePath(text) {
  return text.split(";").filter((s) => s.trim()).map((s) => {
    const [e, l] = s.split("@");
    return {eye: vec3(e), look: l ? vec3(l) : null};
  });
}
