---@meta linalg
-- LuaLS definitions of `require("linalg")` (vectors, matrices, quaternions, rigid transforms;
-- README, "Linear algebra") and of the module-type data tables (world.module_type,
-- module.type_data). Indices start at 1.

---A link, joint and dock description of a module type (poses in the module frame at zero angles).
---@class ModuleTypeData
---@field name string
---@field file string
---@field root string
---@field mass number
---@field links {name: string, mass: number, com: number[]}[]
---@field joints {name: string, parent: string, child: string, pivot: number[], axis: number[], lower: number, upper: number, continuous: boolean, torque: number, speed: number, gain: number, stiffness: number}[]
---@field docks {name: string, link: string, at: number[], normal: number[], up: number[], quat: number[], gender: string, size: number, symmetry: integer, strength: number, strength_torque: number}[]

---A dense matrix or a vector (an n x 1 column made by linalg.vector). Operators: + - * / (by a
---number), unary -, ==, # (entries of a vector, rows of a matrix).
---@class linalg.matrix
---@operator add(linalg.matrix): linalg.matrix
---@operator sub(linalg.matrix): linalg.matrix
---@operator mul(linalg.matrix|number): linalg.matrix
---@operator div(number): linalg.matrix
---@operator unm: linalg.matrix
---@operator len: integer
local Matrix = {}
---@return integer
function Matrix:rows() end
---@return integer
function Matrix:cols() end
---A:get(i, j), or v:get(i) for a vector.
---@param i integer
---@param j? integer
---@return number
function Matrix:get(i, j) end
---A:set(i, j, x), or v:set(i, x) for a vector; returns the matrix.
---@param i integer
---@param j number
---@param x? number
---@return linalg.matrix
function Matrix:set(i, j, x) end
---Transpose.
---@return linalg.matrix
function Matrix:t() end
---Inverse; an error when singular.
---@return linalg.matrix
function Matrix:inv() end
---@return number
function Matrix:det() end
---x with A x = b (least squares when A is not square).
---@param b linalg.matrix
---@return linalg.matrix
function Matrix:solve(b) end
---Moore-Penrose pseudo-inverse.
---@param tol? number
---@return linalg.matrix
function Matrix:pinv(tol) end
---Thin SVD: A = U diag(s) V^T.
---@return linalg.matrix U
---@return linalg.matrix s
---@return linalg.matrix V
function Matrix:svd() end
---Damped least squares (A^T A + lambda^2 I)^-1 A^T b.
---@param b linalg.matrix
---@param lambda number
---@return linalg.matrix
function Matrix:dls(b, lambda) end
---@return number
function Matrix:norm() end
---@param w linalg.matrix
---@return number
function Matrix:dot(w) end
---@param w linalg.matrix|number[]
---@return linalg.matrix
function Matrix:cross(w) end
---@return linalg.matrix
function Matrix:normalized() end
---@return linalg.matrix
function Matrix:copy() end
---Rows as nested tables, or a flat table for a vector.
---@return table
function Matrix:totable() end

---A unit quaternion. q * r composes, q * v rotates a 3-vector.
---@class linalg.quat
---@operator mul(linalg.quat): linalg.quat
local Quat = {}
---@param v linalg.matrix|number[]
---@return linalg.matrix
function Quat:rotate(v) end
---@return linalg.quat
function Quat:inv() end
---@return linalg.matrix 3 x 3 rotation
function Quat:matrix() end
---@return number radians, 0..pi
function Quat:angle() end
---@return number[] {w, x, y, z}
function Quat:totable() end

---A rigid transform. T * U composes, T * v applies to a point.
---@class linalg.transform
---@operator mul(linalg.transform): linalg.transform
local Transform = {}
---@return linalg.transform
function Transform:inv() end
---@return linalg.quat
function Transform:rotation() end
---@return linalg.matrix
function Transform:translation() end
---@return linalg.matrix 4 x 4 homogeneous
function Transform:matrix() end

local linalg = {}
---A matrix from its rows: linalg.matrix{{1, 2}, {3, 4}}.
---@param rows number[][]
---@return linalg.matrix
function linalg.matrix(rows) end
---A vector from its entries, or n zeros.
---@param entries number[]|integer
---@return linalg.matrix
function linalg.vector(entries) end
---@param n integer
---@return linalg.matrix
function linalg.identity(n) end
---An r x c zero matrix, or a zero vector of r entries.
---@param r integer
---@param c? integer
---@return linalg.matrix
function linalg.zeros(r, c) end
---linalg.quat(w, x, y, z) or linalg.quat{w, x, y, z}; normalised.
---@param w number|number[]
---@param x? number
---@param y? number
---@param z? number
---@return linalg.quat
function linalg.quat(w, x, y, z) end
---@param axis linalg.matrix|number[]
---@param angle number
---@return linalg.quat
function linalg.quat_axis_angle(axis, angle) end
---@param R? linalg.quat|linalg.matrix
---@param p? linalg.matrix|number[]
---@return linalg.transform
function linalg.transform(R, p) end

return linalg
