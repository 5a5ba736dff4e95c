/* New numpy arrays from C without a Python call (included by lcp/_lemke_c.c, after _lemke_py.h):
 * numpy's own PyArray_NewFromDescr, found at run time in the table numpy publishes for C
 * extensions (the capsule numpy._core._multiarray_umath._ARRAY_API), so that the build still
 * needs no numpy headers. numpy keeps that table's order as its C ABI: entry 0 is
 * PyArray_GetNDArrayCVersion, 2 the ndarray type, 94 PyArray_NewFromDescr (numpy/
 * __multiarray_api.h of numpy 1.x and 2.x alike); the data pointer is the first field after the
 * object header (PyArrayObject_fields, read by numpy's PyArray_DATA macro).
 *
 *   array_setup(capsule, float64, intp, ndarray) -> bool: the table, taken when its ABI version
 *     is numpy 1.x's (0x01000009) or 2.x's (0x02000000) and its ndarray type is `ndarray`
 *     (None, or any mismatch: off, and numpy.empty is called as before). lcp/_lemke_kernel.py's
 *     `numpy_arrays` then checks arrays made here against numpy.empty's (array_probe) and turns
 *     the route off when they differ in anything.
 *   array_probe(shape, integer) -> an array made by new_array_of, its entries 0, 1, 2, ...
 *     written through the data pointer read here.
 *
 * What numpy.empty(shape[, numpy.intp]) did (its argument parsing, the shape's conversion) and
 * the buffer request that followed were 0.1-0.15 us of the 0.6 us the small solve spends on its
 * five arrays at n = 10; PyArray_NewFromDescr is the call numpy.empty itself ends in, with the
 * same arguments (the ndarray type, the dtype, the shape, no strides, no data, C order), so the
 * arrays are the same: float64 or intp, C-contiguous, owning their data. */
#ifndef RIGIDLCP_NUMPY_ABI_H
#define RIGIDLCP_NUMPY_ABI_H

typedef PyObject *(*NewFromDescr)(PyTypeObject *, PyObject *, int, const Py_ssize_t *,
                                  const Py_ssize_t *, void *, int, PyObject *);
static NewFromDescr s_new_from_descr; /* NULL: the route is off */
static PyObject *s_arr_f64, *s_arr_intp;
static PyTypeObject *s_arr_type;

static PyObject *py_array_setup(PyObject *self, PyObject *args)
{
    PyObject *capsule, *f64, *intp, *nd;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOO!", &capsule, &f64, &intp, &PyType_Type, &nd)) return NULL;
    s_new_from_descr = NULL;
    if (capsule == Py_None || !PyCapsule_CheckExact(capsule)) Py_RETURN_FALSE;
    void **api = (void **)PyCapsule_GetPointer(capsule, NULL);
    if (!api) {
        PyErr_Clear();
        Py_RETURN_FALSE;
    }
    unsigned int abi = ((unsigned int (*)(void))api[0])();
    if ((abi != 0x01000009u && abi != 0x02000000u) || (PyTypeObject *)api[2] != (PyTypeObject *)nd)
        Py_RETURN_FALSE;
    PyObject **slots[2] = {&s_arr_f64, &s_arr_intp};
    PyObject *given[2] = {f64, intp};
    for (int k = 0; k < 2; k++) {
        Py_INCREF(given[k]);
        Py_XSETREF(*slots[k], given[k]);
    }
    Py_INCREF(nd);
    Py_XSETREF(s_arr_type, (PyTypeObject *)nd);
    s_new_from_descr = (NewFromDescr)api[94];
    Py_RETURN_TRUE;
}

/* The data pointer of an array made by new_array_of (PyArray_DATA). */
static inline void *array_data(PyObject *arr)
{
    return *(void **)((char *)arr + sizeof(PyObject));
}

/* A new C-ordered array of nd (1 or 2) dimensions dims, float64 (integer 0) or intp: numpy's
 * PyArray_NewFromDescr when array_setup found it, else numpy.empty(shape[, intp]) (`empty`,
 * `intp`: the objects the caller holds). *data receives its data pointer (the buffer is
 * C-contiguous and writable: the array is new). NULL with an error. */
static PyObject *new_array_of(int nd, const Py_ssize_t *dims, int integer, PyObject *empty,
                              PyObject *intp, void **data)
{
    if (s_new_from_descr) {
        PyObject *descr = integer ? s_arr_intp : s_arr_f64;
        Py_INCREF(descr); /* stolen by PyArray_NewFromDescr, even when it fails */
        PyObject *arr = s_new_from_descr(s_arr_type, descr, nd, dims, NULL, NULL, 0, NULL);
        if (arr) *data = array_data(arr);
        return arr;
    }
    PyObject *shape = nd == 1 ? PyLong_FromSsize_t(dims[0])
                              : Py_BuildValue("(nn)", dims[0], dims[1]);
    if (!shape) return NULL;
    PyObject *call[2] = {shape, intp};
    PyObject *arr = PyObject_Vectorcall(empty, call, integer ? 2 : 1, NULL);
    Py_DECREF(shape);
    if (!arr) return NULL;
    Py_buffer v;
    if (PyObject_GetBuffer(arr, &v, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) {
        Py_DECREF(arr);
        return NULL;
    }
    Py_ssize_t bytes = (Py_ssize_t)(integer ? sizeof(Py_ssize_t) : sizeof(double)) * dims[0] *
                       (nd == 2 ? dims[1] : 1);
    int ok = v.len == bytes;
    *data = v.buf; /* the array owns its data: the pointer stays valid after the release */
    PyBuffer_Release(&v);
    if (!ok) {
        PyErr_SetString(PyExc_ValueError, "numpy.empty gave an array of another size");
        Py_DECREF(arr);
        return NULL;
    }
    return arr;
}

/* The fields numpy's PyArray_DATA / NDIM / DIMS / STRIDES / DESCR / FLAGS macros read, in the
 * order of PyArrayObject_fields (numpy 1.x and 2.x alike: the ABI array_setup checked). Read
 * only when s_fields_ok: lcp/_lemke_kernel.py's `numpy_arrays` compares what array_fields
 * reads with numpy's own attributes on probes (C and Fortran order, views, read-only, 0-d to
 * 2-d, float64 and others) and sets it with array_fields_use(True). */
typedef struct {
    PyObject_HEAD
    char *data;
    int nd;
    Py_ssize_t *dimensions;
    Py_ssize_t *strides;
    PyObject *base;
    PyObject *descr;
    int flags;
} ArrayFields;
#define ARR_C_CONTIGUOUS 0x0001
#define ARR_WRITEABLE 0x0400
#define ARR_WARN_ON_WRITE (1u << 31) /* numpy's private flag: a write warns (buffer route) */
static int s_fields_ok;

/* array_fields(arr) -> (data address, nd, shape, strides, descr, C-contiguous, writeable): the
 * fields as read here (arr an ndarray exactly), for the check. */
static PyObject *py_array_fields(PyObject *self, PyObject *arr)
{
    (void)self;
    if (!s_arr_type || Py_TYPE(arr) != s_arr_type) {
        PyErr_SetString(PyExc_TypeError, "array_fields: a numpy.ndarray (after array_setup)");
        return NULL;
    }
    const ArrayFields *a = (const ArrayFields *)arr;
    if (a->nd < 0 || a->nd > 32) {
        PyErr_SetString(PyExc_ValueError, "array_fields: nd out of range");
        return NULL;
    }
    PyObject *shape = PyTuple_New(a->nd), *strides = PyTuple_New(a->nd);
    for (int k = 0; shape && strides && k < a->nd; k++) {
        PyTuple_SET_ITEM(shape, k, PyLong_FromSsize_t(a->dimensions[k]));
        PyTuple_SET_ITEM(strides, k, PyLong_FromSsize_t(a->strides[k]));
    }
    PyObject *out = shape && strides && !PyErr_Occurred()
                        ? Py_BuildValue("(KiOOOOO)", (unsigned long long)(uintptr_t)a->data, a->nd,
                                        shape, strides, a->descr,
                                        (a->flags & ARR_C_CONTIGUOUS) ? Py_True : Py_False,
                                        (a->flags & ARR_WRITEABLE) ? Py_True : Py_False)
                        : NULL;
    Py_XDECREF(shape);
    Py_XDECREF(strides);
    return out;
}

/* array_fields_use(flag) -> flag: the route of plain_f64 on or off. */
static PyObject *py_array_fields_use(PyObject *self, PyObject *flag)
{
    (void)self;
    int on = PyObject_IsTrue(flag);
    if (on < 0) return NULL;
    s_fields_ok = on && s_arr_type != NULL;
    return PyBool_FromLong(s_fields_ok);
}

/* The data of obj when it is exactly a numpy.ndarray whose dtype object is `f64` (numpy's
 * float64 itself: native doubles), C-contiguous (and writeable, when `writeable`), of nd (1 or
 * 2) dimensions all equal to n: read from its fields, without a buffer request (numpy builds and caches a buffer
 * description at an array's first request: 0.1 us for each new M and q of the natural call);
 * else NULL (the caller asks for a buffer, with its checks and errors). The array is the
 * caller's, held for as long as the pointer is used. */
static const double *plain_f64(PyObject *obj, PyObject *f64, int nd, Py_ssize_t n,
                               int writeable)
{
    if (!s_fields_ok || Py_TYPE(obj) != s_arr_type) return NULL;
    const ArrayFields *a = (const ArrayFields *)obj;
    const unsigned int flags = (unsigned int)a->flags,
                       need = ARR_C_CONTIGUOUS | (writeable ? ARR_WRITEABLE : 0);
    if (a->descr != f64 || a->nd != nd || (flags & ARR_WARN_ON_WRITE) || (flags & need) != need)
        return NULL;
    for (int k = 0; k < nd; k++)
        if (a->dimensions[k] != n) return NULL;
    return (const double *)a->data;
}

static PyObject *py_array_probe(PyObject *self, PyObject *args)
{
    PyObject *shape;
    int integer;
    (void)self;
    if (!PyArg_ParseTuple(args, "O!p", &PyTuple_Type, &shape, &integer)) return NULL;
    Py_ssize_t nd = PyTuple_GET_SIZE(shape), dims[2] = {0, 0};
    if (nd < 1 || nd > 2) {
        PyErr_SetString(PyExc_ValueError, "array_probe: one or two dimensions");
        return NULL;
    }
    for (Py_ssize_t k = 0; k < nd; k++)
        if ((dims[k] = PyLong_AsSsize_t(PyTuple_GET_ITEM(shape, k))) < 0) {
            if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "array_probe: size < 0");
            return NULL;
        }
    if (!s_new_from_descr) {
        PyErr_SetString(PyExc_RuntimeError, "array_probe: the route is off (array_setup)");
        return NULL;
    }
    void *data;
    PyObject *arr = new_array_of((int)nd, dims, integer, NULL, NULL, &data);
    if (!arr) return NULL;
    Py_ssize_t size = dims[0] * (nd == 2 ? dims[1] : 1);
    for (Py_ssize_t i = 0; i < size; i++)
        if (integer)
            ((Py_ssize_t *)data)[i] = i;
        else
            ((double *)data)[i] = (double)i;
    return arr;
}

#endif /* RIGIDLCP_NUMPY_ABI_H */
