-- Small vector and quaternion helpers for world scripts and module types:
-- `local vec = require("vec")`. Vectors are {x, y, z} arrays, quaternions {w, x, y, z} arrays;
-- vec.v3 and vec.q4 also accept the keyed tables that m:position() and m:orientation() return.
local vec = {}

function vec.v3(t) return {t[1] or t.x, t[2] or t.y, t[3] or t.z} end
function vec.q4(t) return {t[1] or t.w, t[2] or t.x, t[3] or t.y, t[4] or t.z} end
function vec.add(a, b) return {a[1] + b[1], a[2] + b[2], a[3] + b[3]} end
function vec.sub(a, b) return {a[1] - b[1], a[2] - b[2], a[3] - b[3]} end
function vec.scale(a, s) return {a[1] * s, a[2] * s, a[3] * s} end
function vec.dot(a, b) return a[1] * b[1] + a[2] * b[2] + a[3] * b[3] end
function vec.norm(a) return math.sqrt(vec.dot(a, a)) end
function vec.dist(a, b) return vec.norm(vec.sub(a, b)) end

--- Quaternion product a * b.
function vec.qmul(a, b)
  return {a[1] * b[1] - a[2] * b[2] - a[3] * b[3] - a[4] * b[4],
          a[1] * b[2] + a[2] * b[1] + a[3] * b[4] - a[4] * b[3],
          a[1] * b[3] - a[2] * b[4] + a[3] * b[1] + a[4] * b[2],
          a[1] * b[4] + a[2] * b[3] - a[3] * b[2] + a[4] * b[1]}
end
function vec.qconj(q) return {q[1], -q[2], -q[3], -q[4]} end
--- Rotation of `angle` radians about a unit `axis`.
function vec.qaxis(axis, angle)
  local s = math.sin(angle / 2)
  return {math.cos(angle / 2), axis[1] * s, axis[2] * s, axis[3] * s}
end
--- v rotated by q (q may be keyed, as m:orientation() returns it).
function vec.qrot(q, v)
  q = vec.q4(q)
  local p = vec.qmul(vec.qmul(q, {0, v[1], v[2], v[3]}), vec.qconj(q))
  return {p[2], p[3], p[4]}
end

return vec
