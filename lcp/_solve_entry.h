/* lcp.solve as a callable object whose default call goes straight to C (included by
 * lcp/_lemke_c.c after _lemke_solution.h). lcp/api.py's `solve` stays the Python function it
 * is; api wraps it as `Entry(solve, LCP, globals())` when the extension is built:
 *
 *   entry(problem) and entry(problem, "lemke"), problem an lcp.LCP (exactly), no keywords:
 *     api._FAST(problem) -- read from api's globals at every call, so that a patched or
 *     re-registered path is honoured; None until api loaded it -- and, when that gives None,
 *     api._general(problem, "lemke", None, True, False, {}): what `solve` does for that call,
 *     without its Python frame (a fifth of the time of a prebuilt call at n = 10).
 *   Any other call: `solve(*args, **kwargs)` itself.
 *
 * The object passes for the function: __doc__, __name__, __qualname__, __module__ and
 * __wrapped__ (inspect.signature follows it) are the function's, other attributes are read
 * from it, repr is its repr, and it pickles by name. */
#ifndef RIGIDLCP_SOLVE_ENTRY_H
#define RIGIDLCP_SOLVE_ENTRY_H

typedef struct {
    PyObject_HEAD
    PyObject *func;    /* lcp.api.solve, the Python function */
    PyObject *lcp;     /* lcp.LCP */
    PyObject *globals; /* lcp.api's globals: _FAST and _general, read at every call */
    vectorcallfunc vectorcall;
} Entry;

static PyObject *s_fast_key, *s_general_key, *s_lemke_name;

static PyObject *entry_call(PyObject *self, PyObject *const *args, size_t nargsf,
                            PyObject *kwnames)
{
    Entry *e = (Entry *)self;
    Py_ssize_t nargs = PyVectorcall_NARGS(nargsf);
    if (!kwnames && nargs >= 1 && Py_TYPE(args[0]) == (PyTypeObject *)e->lcp &&
        (nargs == 1 || (nargs == 2 && PyUnicode_CheckExact(args[1]) &&
                        PyUnicode_Compare(args[1], s_lemke_name) == 0))) {
        PyObject *fast = PyDict_GetItemWithError(e->globals, s_fast_key); /* borrowed */
        if (fast && fast != Py_None) {
            PyObject *sol = PyObject_CallOneArg(fast, args[0]);
            if (sol != Py_None) return sol; /* the Solution, or NULL: the error */
            Py_DECREF(sol);
            PyObject *general = PyDict_GetItemWithError(e->globals, s_general_key);
            PyObject *options = general ? PyDict_New() : NULL;
            if (!options) {
                if (!PyErr_Occurred())
                    PyErr_SetString(PyExc_RuntimeError, "lcp.api._general is missing");
                return NULL;
            }
            PyObject *call[6] = {args[0], s_lemke_name, Py_None, Py_True, Py_False, options};
            PyObject *out = PyObject_Vectorcall(general, call, 6, NULL);
            Py_DECREF(options);
            return out;
        }
        if (PyErr_Occurred()) return NULL;
    }
    return PyObject_Vectorcall(e->func, args, nargsf, kwnames);
}

static PyObject *entry_new(PyTypeObject *type, PyObject *args, PyObject *kwds)
{
    PyObject *func, *lcp, *globals;
    if (kwds && PyDict_GET_SIZE(kwds)) {
        PyErr_SetString(PyExc_TypeError, "Entry(solve, LCP, globals): no keywords");
        return NULL;
    }
    if (!PyArg_ParseTuple(args, "OO!O!", &func, &PyType_Type, &lcp, &PyDict_Type, &globals))
        return NULL;
    if (!s_fast_key && (!(s_fast_key = PyUnicode_InternFromString("_FAST")) ||
                        !(s_general_key = PyUnicode_InternFromString("_general")) ||
                        !(s_lemke_name = PyUnicode_InternFromString("lemke"))))
        return NULL;
    Entry *e = (Entry *)type->tp_alloc(type, 0);
    if (!e) return NULL;
    e->func = Py_NewRef(func);
    e->lcp = Py_NewRef(lcp);
    e->globals = Py_NewRef(globals);
    e->vectorcall = entry_call;
    return (PyObject *)e;
}

static int entry_traverse(PyObject *self, visitproc visit, void *arg)
{
    Entry *e = (Entry *)self;
    Py_VISIT(e->func);
    Py_VISIT(e->lcp);
    Py_VISIT(e->globals);
    return 0;
}

static int entry_clear(PyObject *self)
{
    Entry *e = (Entry *)self;
    Py_CLEAR(e->func);
    Py_CLEAR(e->lcp);
    Py_CLEAR(e->globals);
    return 0;
}

static void entry_dealloc(PyObject *self)
{
    PyObject_GC_UnTrack(self);
    entry_clear(self);
    Py_TYPE(self)->tp_free(self);
}

/* The function's attributes: generic lookup first (the getters below, the type's methods),
 * then the function's own. */
static PyObject *entry_getattro(PyObject *self, PyObject *name)
{
    PyObject *out = PyObject_GenericGetAttr(self, name);
    if (out || !PyErr_ExceptionMatches(PyExc_AttributeError)) return out;
    PyErr_Clear();
    return PyObject_GetAttr(((Entry *)self)->func, name);
}

static PyObject *entry_attr(PyObject *self, void *name)
{
    return PyObject_GetAttrString(((Entry *)self)->func, (const char *)name);
}

static PyObject *entry_wrapped(PyObject *self, void *unused)
{
    (void)unused;
    return Py_NewRef(((Entry *)self)->func);
}

static PyObject *entry_repr(PyObject *self) { return PyObject_Repr(((Entry *)self)->func); }

static PyObject *entry_reduce(PyObject *self, PyObject *unused)
{
    (void)unused; /* pickled as the module global it is (lcp.api.solve) */
    return PyObject_GetAttrString(((Entry *)self)->func, "__qualname__");
}

static PyGetSetDef entry_getset[] = {
    {"__doc__", entry_attr, NULL, NULL, "__doc__"},
    {"__name__", entry_attr, NULL, NULL, "__name__"},
    {"__qualname__", entry_attr, NULL, NULL, "__qualname__"},
    {"__module__", entry_attr, NULL, NULL, "__module__"},
    {"__wrapped__", entry_wrapped, NULL, NULL, NULL},
    {NULL, NULL, NULL, NULL, NULL}};

static PyMethodDef entry_methods[] = {{"__reduce__", entry_reduce, METH_NOARGS, NULL},
                                      {NULL, NULL, 0, NULL}};

static PyTypeObject EntryType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "rigidlcp.lcp._lemke_c.Entry",
    .tp_basicsize = sizeof(Entry),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC | Py_TPFLAGS_HAVE_VECTORCALL,
    .tp_vectorcall_offset = offsetof(Entry, vectorcall),
    .tp_call = PyVectorcall_Call,
    .tp_new = entry_new,
    .tp_traverse = entry_traverse,
    .tp_clear = entry_clear,
    .tp_dealloc = entry_dealloc,
    .tp_getattro = entry_getattro,
    .tp_repr = entry_repr,
    .tp_getset = entry_getset,
    .tp_methods = entry_methods,
};

#endif /* RIGIDLCP_SOLVE_ENTRY_H */
