/* The check of an array argument of the C extensions (included by lcp/_lemke_py.h and
 * lcp/solvers/_pivot_c.c): a writable, contiguous buffer of `size` float64 ('d') or int64
 * values, else ValueError naming the argument. The includer includes <Python.h> and defines
 * `idx` (Py_ssize_t). */
#ifndef RIGIDLCP_BUFFER_H
#define RIGIDLCP_BUFFER_H

/* fortran: column-major contiguous (else row-major). */
static int get_buffer(PyObject *obj, Py_buffer *view, const char *name, char kind, idx size,
                      int fortran)
{
    int flags = PyBUF_WRITABLE | PyBUF_FORMAT | (fortran ? PyBUF_F_CONTIGUOUS : PyBUF_C_CONTIGUOUS);
    if (PyObject_GetBuffer(obj, view, flags) < 0) return -1;
    const char *f = view->format ? view->format : "B";
    if (*f == '<' || *f == '=' || *f == '@') f++;
    int ok = view->itemsize == 8 &&
             (kind == 'd' ? (f[0] == 'd' && f[1] == 0)
                          : ((f[0] == 'l' || f[0] == 'q') && f[1] == 0));
    if (!ok || view->len / 8 != size) {
        PyErr_Format(PyExc_ValueError, "%s: expected %zd %s values", name, size,
                     kind == 'd' ? "float64" : "int64");
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

#endif /* RIGIDLCP_BUFFER_H */
