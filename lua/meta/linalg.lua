---@meta linalg
-- LuaLS definitions of `require("linalg")` (vectors, matrices, quaternions, rigid transforms;
-- docs/api/lua.md, "Linear algebra"; generated from docs/api/lua_api.lua) and of the module-type data tables (world.module_type,
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
---The number of rows.
---@return integer
function Matrix:rows() end
---The number of columns.
---@return integer
function Matrix:cols() end
---Entry (i, j), or entry i of a vector.
---@param i integer
---@param j? integer
---@return number
function Matrix:get(i, j) end
---Sets entry (i, j) to x (or entry i of a vector to j) and returns the matrix.
---@param i integer
---@param j number
---@param x? number
---@return linalg.matrix
function Matrix:set(i, j, x) end
---Transpose (of a vector: a 1 x n matrix).
---@return linalg.matrix
function Matrix:t() end
---The inverse (an error when singular).
---@return linalg.matrix
function Matrix:inv() end
---The determinant of a square matrix.
---@return number
function Matrix:det() end
---X with A x = b (b a vector or a matrix); least squares when A is not square; an error when a square A is singular.
---@param b linalg.matrix
---@return linalg.matrix
function Matrix:solve(b) end
---Moore-Penrose pseudo-inverse (singular values below tol, default eps x max(r, c) x the largest, count as zero).
---@param tol? number
---@return linalg.matrix
function Matrix:pinv(tol) end
---Thin SVD: A = U diag(s) Vᵀ, s a vector in descending order.
---@return linalg.matrix U
---@return linalg.matrix s
---@return linalg.matrix V
function Matrix:svd() end
---Damped least squares `(AᵀA + λ²I)⁻¹Aᵀb`, solved through the smaller of AᵀA and AAᵀ.
---@param b linalg.matrix
---@param lambda number
---@return linalg.matrix
function Matrix:dls(b, lambda) end
---The Euclidean norm (the Frobenius norm for a matrix).
---@return number
function Matrix:norm() end
---The dot product with a vector of the same size.
---@param w linalg.matrix
---@return number
function Matrix:dot(w) end
---The cross product with another 3-vector.
---@param w linalg.matrix|number[]
---@return linalg.matrix
function Matrix:cross(w) end
---The vector scaled to unit length.
---@return linalg.matrix
function Matrix:normalized() end
---A copy.
---@return linalg.matrix
function Matrix:copy() end
---Plain nested tables (rows), or a flat table for a vector.
---@return table
function Matrix:totable() end

---A unit quaternion. q * r composes, q * v rotates a 3-vector.
---@class linalg.quat
---@operator mul(linalg.quat): linalg.quat
local Quat = {}
---The 3-vector v rotated by the quaternion (as `q * v`).
---@param v linalg.matrix|number[]
---@return linalg.matrix
function Quat:rotate(v) end
---The inverse rotation (the conjugate).
---@return linalg.quat
function Quat:inv() end
---The 3 x 3 rotation matrix.
---@return linalg.matrix 3 x 3 rotation
function Quat:matrix() end
---The rotation angle, radians, 0 to pi.
---@return number radians, 0..pi
function Quat:angle() end
---The quaternion as `{w, x, y, z}`.
---@return number[] {w, x, y, z}
function Quat:totable() end

---A rigid transform. T * U composes, T * v applies to a point.
---@class linalg.transform
---@operator mul(linalg.transform): linalg.transform
local Transform = {}
---The inverse transform.
---@return linalg.transform
function Transform:inv() end
---The rotation part, a quaternion.
---@return linalg.quat
function Transform:rotation() end
---The translation part, a 3-vector.
---@return linalg.matrix
function Transform:translation() end
---The 4 x 4 homogeneous matrix.
---@return linalg.matrix 4 x 4 homogeneous
function Transform:matrix() end
local linalg = {}
---A matrix from its rows.
---@param rows number[][]
---@return linalg.matrix
function linalg.matrix(rows) end
---A vector (an n x 1 column that stays a vector through products), or n zeros.
---@param entries number[]|integer
---@return linalg.matrix
function linalg.vector(entries) end
---The n x n identity matrix.
---@param n integer
---@return linalg.matrix
function linalg.identity(n) end
---A zero matrix of r x c, or a zero vector of r entries.
---@param r integer
---@param c? integer
---@return linalg.matrix
function linalg.zeros(r, c) end
---A unit quaternion from w, x, y, z or a table `{w, x, y, z}` (normalised when made).
---@param w number|number[]
---@param x? number
---@param y? number
---@param z? number
---@return linalg.quat
function linalg.quat(w, x, y, z) end
---The unit quaternion turning `angle` radians about `axis` (normalised when made).
---@param axis linalg.matrix|number[]
---@param angle number
---@return linalg.quat
function linalg.quat_axis_angle(axis, angle) end
---A rigid transform from a quat or 3 x 3 rotation and a 3-vector (`{x, y, z}` tables work wherever a 3-vector is asked).
---@param R? linalg.quat|linalg.matrix
---@param p? linalg.matrix|number[]
---@return linalg.transform
function linalg.transform(R, p) end
return linalg
